//! The payload's byte order (little-endian 4-byte words) and padding.

use std::io::{self, Write};

use crc32fast::Hasher;

/// The file stores little-endian 4-byte words; every element type here is
/// made of 4-byte words, so on a big-endian host each word is swapped.
#[cfg(target_endian = "big")]
pub(super) fn from_le_words(bytes: &mut [u8]) {
    for w in bytes.chunks_exact_mut(4) {
        w.reverse();
    }
}

#[cfg(target_endian = "little")]
pub(super) fn from_le_words(_bytes: &mut [u8]) {}

/// Zero bytes that pad a section of `len` bytes to the next 8-byte boundary.
pub(super) fn padding(len: u64) -> u64 {
    (8 - len % 8) % 8
}

/// Writes 4-byte words as little-endian (a plain copy on little-endian hosts).
pub(super) fn write_le_words(w: &mut impl Write, bytes: &[u8]) -> io::Result<()> {
    if cfg!(target_endian = "little") {
        w.write_all(bytes)
    } else {
        for word in bytes.chunks_exact(4) {
            w.write_all(&[word[3], word[2], word[1], word[0]])?;
        }
        Ok(())
    }
}

/// Hashes 4-byte words as their little-endian encoding.
pub(super) fn hash_le_words(h: &mut Hasher, bytes: &[u8]) {
    if cfg!(target_endian = "little") {
        h.update(bytes);
    } else {
        for word in bytes.chunks_exact(4) {
            h.update(&[word[3], word[2], word[1], word[0]]);
        }
    }
}
