//! The files a run leaves: each written whole or not at all (a temporary
//! file beside it, renamed into place), so a run cut short by a GPU
//! machine's time limit never leaves half a `gpu.json`.

use std::path::Path;

use anyhow::{Context, Result};

/// Writes `bytes` to `path` through `path` + `.partial`, renamed into place.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".partial");
    let tmp = Path::new(&tmp);
    std::fs::write(tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()))?;
    std::fs::rename(tmp, path).with_context(|| format!("cannot write {}", path.display()))
}
