// Reading the checked-in corpora under `fuzz/`, shared by the stable corpus
// tests of every crate (`include!`d there, so `CARGO_MANIFEST_DIR` is the
// including crate's directory, two levels below the repository root).

use std::path::PathBuf;

/// `fuzz/seeds/<target>`.
pub fn seed_dir(target: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/seeds")
        .join(target)
}

/// Every file of `fuzz/seeds/<target>` (a relative path such as
/// `../regressions/x` reaches the other corpora) as `(file name, bytes)`,
/// sorted by name.
pub fn read_seeds(target: &str) -> Vec<(String, Vec<u8>)> {
    let dir = seed_dir(target);
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| {
            let path = e.expect("directory entry").path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&path).expect("seed file"))
        })
        .collect();
    out.sort();
    out
}
