//! Compiles TetGen 1.5 and our C ABI shim (`cpp/tet_shim.cpp`) when the
//! `tetgen` feature is on.
//!
//! TetGen's source is not committed to this repository: it ships inside the
//! `tritet` registry package (pinned to an exact version in the workspace
//! `Cargo.toml`), which Cargo downloads as an ordinary optional dependency of
//! the `tetgen` feature. tritet's own build compiles TetGen only under its
//! `with_tetgen` feature, which we leave off, so TetGen is compiled exactly
//! once — here, as a library (`-DTETLIBRARY`: errors are thrown, not `exit`)
//! with assertions off (`-DNDEBUG`) — and no symbol is defined twice.
//!
//! The source directory is found, in order:
//! 1. `TET_BUILD_TETGEN_SRC` (a directory holding `tetgen.cxx`, `predicates.cxx`, `tetgen.h`);
//! 2. `$CARGO_HOME/registry/src/*/tritet-<version>/c_code` (the usual place);
//! 3. `cargo metadata` (handles vendored sources and `[patch]`).

use std::env;
use std::path::PathBuf;

#[path = "build/locate.rs"]
mod locate;
use locate::FILES;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=build/locate.rs");
    println!("cargo:rerun-if-changed=cpp/tet_shim.cpp");
    println!("cargo:rerun-if-changed=cpp/tet_shim.h");
    println!("cargo:rerun-if-env-changed=TET_BUILD_TETGEN_SRC");
    // The target triple, for the test of the `cargo metadata` route.
    if let Ok(target) = env::var("TARGET") {
        println!("cargo:rustc-env=TET_BUILD_TARGET={target}");
    }
    if env::var_os("CARGO_FEATURE_TETGEN").is_none() {
        return;
    }
    let src = match find_tetgen() {
        Ok(dir) => dir,
        Err(why) => panic!(
            "tet-build (feature `tetgen`): cannot find TetGen's source ({why}). \
             Run `cargo fetch`, or set TET_BUILD_TETGEN_SRC to a directory holding {FILES:?}, \
             or build with --no-default-features."
        ),
    };
    for f in FILES {
        println!("cargo:rerun-if-changed={}", src.join(f).display());
    }
    let mut build = cc::Build::new();
    build
        .cpp(true)
        .include(&src)
        .include("cpp")
        .define("TETLIBRARY", None)
        .define("NDEBUG", None)
        // TetGen's robustness relies on its own exact predicates: never let
        // the compiler contract or reassociate floating-point operations.
        .flag_if_supported("-ffp-contract=off")
        .flag_if_supported("-fno-fast-math")
        .flag_if_supported("-Wno-unused-parameter")
        .flag_if_supported("-Wno-unused-but-set-variable")
        .flag_if_supported("-Wno-unused-variable")
        .flag_if_supported("-Wno-maybe-uninitialized")
        .flag_if_supported("-Wno-int-to-pointer-cast")
        .flag_if_supported("-Wno-sign-compare")
        .flag_if_supported("-Wno-misleading-indentation")
        .flag_if_supported("-Wno-class-memaccess")
        .flag_if_supported("-Wno-format-overflow")
        .warnings(false)
        .file(src.join("predicates.cxx"))
        .file(src.join("tetgen.cxx"))
        .file("cpp/tet_shim.cpp");
    // TetGen is slow without optimisation even in debug test builds.
    build.opt_level(2);
    build.compile("tet_build_tetgen");
}

fn find_tetgen() -> Result<PathBuf, String> {
    if let Some(dir) = env::var_os("TET_BUILD_TETGEN_SRC") {
        let dir = PathBuf::from(dir);
        return if locate::has_sources(&dir) {
            Ok(dir)
        } else {
            Err(format!(
                "TET_BUILD_TETGEN_SRC={} lacks {FILES:?}",
                dir.display()
            ))
        };
    }
    let cargo_home = env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")));
    if let Some(dir) = cargo_home.and_then(|home| locate::from_registry(&home)) {
        return Ok(dir);
    }
    let cargo = env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").map_err(|e| e.to_string())?)
        .join("Cargo.toml");
    let target = env::var("TARGET").map_err(|e| e.to_string())?;
    locate::from_cargo_metadata(&cargo, &manifest, &target)
}
