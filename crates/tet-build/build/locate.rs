//! Where TetGen's source (shipped inside the `tritet` registry package) lies.
//!
//! Shared by the build script (`build.rs`, `#[path]` module) and the test
//! `tests/tetgen.rs`, which checks the `cargo metadata` route against the
//! registry route so the fallback cannot rot unnoticed.

// Each includer uses a different subset.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Must equal the exact pin of `tritet` in the workspace `Cargo.toml`.
pub const TRITET_VERSION: &str = "3.4.0";
/// The TetGen files the build compiles.
pub const FILES: [&str; 3] = ["tetgen.cxx", "predicates.cxx", "tetgen.h"];

/// True when `dir` holds every file of [`FILES`].
pub fn has_sources(dir: &Path) -> bool {
    FILES.iter().all(|f| dir.join(f).is_file())
}

/// `<cargo_home>/registry/src/*/tritet-<version>/c_code`, the usual place
/// (first in sorted order when several registries have it).
pub fn from_registry(cargo_home: &Path) -> Option<PathBuf> {
    let registry = cargo_home.join("registry").join("src");
    let mut candidates: Vec<PathBuf> = std::fs::read_dir(registry)
        .ok()?
        .flatten()
        .map(|e| {
            e.path()
                .join(format!("tritet-{TRITET_VERSION}"))
                .join("c_code")
        })
        .filter(|d| has_sources(d))
        .collect();
    candidates.sort();
    candidates.into_iter().next()
}

/// Asks Cargo (`cargo metadata --offline`) where the `tritet` package of the
/// pinned version lives: handles vendored sources, `[patch]` and a
/// non-default `CARGO_HOME` layout. Only the packages of `target` (a target
/// triple) are resolved, so an offline cache that holds what this build
/// downloaded (not every other platform's dependencies) suffices.
pub fn from_cargo_metadata(cargo: &str, manifest: &Path, target: &str) -> Result<PathBuf, String> {
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--format-version",
            "1",
            "--offline",
            "--filter-platform",
            target,
            "--manifest-path",
        ])
        .arg(manifest)
        .output()
        .map_err(|e| format!("cargo metadata: {e}"))?;
    if !out.status.success() {
        return Err(format!(
            "cargo metadata failed: {}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let json: serde_json::Value =
        serde_json::from_slice(&out.stdout).map_err(|e| format!("cargo metadata JSON: {e}"))?;
    let packages = json["packages"]
        .as_array()
        .ok_or("no packages in cargo metadata")?;
    for p in packages {
        if p["name"] == "tritet"
            && p["version"] == TRITET_VERSION
            && let Some(m) = p["manifest_path"].as_str()
        {
            let dir = Path::new(m)
                .parent()
                .unwrap_or(Path::new("."))
                .join("c_code");
            if has_sources(&dir) {
                return Ok(dir);
            }
        }
    }
    Err(format!(
        "package tritet {TRITET_VERSION} not found by cargo metadata"
    ))
}
