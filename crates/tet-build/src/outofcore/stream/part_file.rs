//! Part files: one finished part on disk, in a directory removed when done.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::outofcore::error::StreamError;
use crate::outofcore::parts::PartStats;

/// One finished part: its file and report fields.
pub(crate) struct PartFile {
    pub(crate) path: PathBuf,
    pub(crate) stats: PartStats,
}

/// A directory for part files, removed with everything in it on drop.
#[derive(Debug)]
pub(crate) struct PartDir(pub(crate) PathBuf);

impl PartDir {
    /// Makes a fresh directory inside `base`.
    pub(crate) fn create(base: &Path) -> Result<PartDir, StreamError> {
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let dir = base.join(format!(
            ".tet-parts-{}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir(&dir).map_err(|source| StreamError::WorkDir {
            dir: dir.clone(),
            source,
        })?;
        Ok(PartDir(dir))
    }
}

impl Drop for PartDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
