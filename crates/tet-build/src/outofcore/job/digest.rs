//! Content digests of the job's files: XXH64 (seed 0), the 64-bit hash of
//! the xxHash family, written as `xxh64:` and 16 lowercase hex digits.
//!
//! A digest names the *content* of a part's input and result, so a re-run
//! can tell a finished part of this plan from a stale or half-written one.
//! It guards against accidents (an old plan's file, a truncated write), not
//! against an adversary: XXH64 is not a cryptographic hash.

use std::io::Read;
use std::path::Path;

/// A streaming XXH64 hasher (seed 0; the `xxhash-rust` crate) that also
/// counts the bytes it has seen.
#[derive(Clone)]
pub struct Xxh64 {
    state: xxhash_rust::xxh64::Xxh64,
    total: u64,
}

impl std::fmt::Debug for Xxh64 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Xxh64").field("total", &self.total).finish()
    }
}

impl Default for Xxh64 {
    fn default() -> Self {
        Xxh64 {
            state: xxhash_rust::xxh64::Xxh64::new(0),
            total: 0,
        }
    }
}

impl Xxh64 {
    /// A fresh hasher.
    pub fn new() -> Xxh64 {
        Xxh64::default()
    }

    /// Adds `data`.
    pub fn update(&mut self, data: &[u8]) {
        self.state.update(data);
        self.total += data.len() as u64;
    }

    /// The hash of everything added so far.
    pub fn finish(&self) -> u64 {
        self.state.digest()
    }
}

/// XXH64 of `data`.
pub fn xxh64(data: &[u8]) -> u64 {
    xxhash_rust::xxh64::xxh64(data, 0)
}

/// A digest as written in the job's files: `xxh64:` and 16 hex digits.
pub fn format_digest(hash: u64) -> String {
    format!("xxh64:{hash:016x}")
}

/// The digest of `data` ([`format_digest`] of [`xxh64`]).
pub fn digest(data: &[u8]) -> String {
    format_digest(xxh64(data))
}

/// The digest and length of the file at `path`, read in 1 MiB blocks.
pub fn digest_file(path: &Path) -> std::io::Result<(String, u64)> {
    let mut f = std::fs::File::open(path)?;
    let mut h = Xxh64::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    Ok((format_digest(h.finish()), h.total))
}
