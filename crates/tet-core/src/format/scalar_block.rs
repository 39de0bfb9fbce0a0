//! The scalar block's name slot (see the module docs of
//! [`crate::format`]): the field's name as UTF-8, NUL-padded to
//! [`SCALAR_NAME_SLOT`] bytes.

use std::path::Path;

use super::error::FormatError;
use super::spec::SCALAR_NAME_SLOT;
use crate::fields::check_name;

/// The scalar block's name slot: the name's UTF-8 bytes, NUL-padded.
/// `None` when the name does not fit (or holds a control character).
pub(super) fn name_slot(name: &str) -> Option<[u8; SCALAR_NAME_SLOT as usize]> {
    check_name(name).ok()?;
    let mut slot = [0u8; SCALAR_NAME_SLOT as usize];
    slot[..name.len()].copy_from_slice(name.as_bytes());
    Some(slot)
}

/// The scalar field's name from its NUL-padded slot: UTF-8 up to the
/// first NUL, zeros after it.
pub(super) fn decode_name(slot: &[u8], path: &Path) -> Result<String, FormatError> {
    let bad = |detail: String| FormatError::BadField {
        path: path.to_path_buf(),
        field: "scalars name",
        detail,
    };
    let len = slot.iter().position(|&b| b == 0).unwrap_or(slot.len());
    if let Some(k) = slot[len..].iter().position(|&b| b != 0) {
        return Err(bad(format!(
            "byte {} after the name's end is not 0",
            len + k
        )));
    }
    String::from_utf8(slot[..len].to_vec()).map_err(|e| bad(format!("not UTF-8: {e}")))
}
