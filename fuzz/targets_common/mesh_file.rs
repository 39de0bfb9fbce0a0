// Body of the `mesh_file` fuzz target: arbitrary bytes given to the mesh-file
// loader `tet_core::format::from_bytes_with_scene` (mesh + optional scene
// block of camera and lights).
//
// Property: the loader returns `Ok` with a mesh that passes
// `TetMesh::validate` and survives a save/load round trip bit for bit, or a
// typed `FormatError` whose message can be printed — never a panic. (Memory:
// the fuzzer runs under `-rss_limit_mb`/`-malloc_limit_mb`, and the stable
// corpus test bounds the bytes allocated per input with a counting
// allocator.)
//
// Random bytes almost never get past the two CRC-32 checks, so every input
// is also tried a second time with `file_length` and both checksums patched
// to match: mutations then reach the section table, the section reads and
// mesh validation.

use tet_core::format::{self, FormatError, HEADER_LEN};

/// Offsets of the header fields the patching rewrites (see `format`'s docs).
const FILE_LENGTH_AT: usize = 16;
const PAYLOAD_CRC_AT: usize = 168;
const HEADER_CRC_AT: usize = 172;

/// Runs the property on `data` as given and with its length and CRCs patched.
pub fn check(data: &[u8]) {
    check_bytes(data);
    if let Some(patched) = with_consistent_header(data) {
        check_bytes(&patched);
    }
}

/// `data` with `file_length` set to its real length and both CRC-32s
/// recomputed (the CRC scheme of the format: payload over `176..len`, header
/// over `0..172`). `None` when `data` is shorter than the header.
pub fn with_consistent_header(data: &[u8]) -> Option<Vec<u8>> {
    if data.len() < HEADER_LEN {
        return None;
    }
    let mut b = data.to_vec();
    let len = b.len() as u64;
    b[FILE_LENGTH_AT..FILE_LENGTH_AT + 8].copy_from_slice(&len.to_le_bytes());
    let payload = crc32fast::hash(&b[HEADER_LEN..]);
    b[PAYLOAD_CRC_AT..PAYLOAD_CRC_AT + 4].copy_from_slice(&payload.to_le_bytes());
    let header = crc32fast::hash(&b[..HEADER_CRC_AT]);
    b[HEADER_CRC_AT..HEADER_CRC_AT + 4].copy_from_slice(&header.to_le_bytes());
    Some(b)
}

/// The property for one byte string; returns whether it loaded.
pub fn check_bytes(data: &[u8]) -> bool {
    match format::from_bytes_with_scene(data) {
        Ok((mesh, scene)) => {
            if let Err(e) = scene.validate() {
                panic!("from_bytes_with_scene returned an unusable scene: {e}");
            }
            if let Err(e) = mesh.validate() {
                panic!("from_bytes returned a mesh that fails validate(): {e}");
            }
            // Round trip through the writer: same bytes again (bitwise, so
            // attribute NaN payloads and -0.0 count too).
            let written = format::to_bytes_with_scene(&mesh, &scene);
            let (reread, rescene) = match format::from_bytes_with_scene(&written) {
                Ok(m) => m,
                Err(e) => panic!("a loaded mesh, written again, does not load: {e}"),
            };
            assert!(
                format::to_bytes_with_scene(&reread, &rescene) == written,
                "write(load(write(mesh))) differs from write(mesh)"
            );
            assert_eq!(reread.tets, mesh.tets);
            assert_eq!(reread.neighbors, mesh.neighbors);
            assert_eq!(reread.constrained, mesh.constrained);
            assert_eq!(reread.triangle_count, mesh.triangle_count);
            true
        }
        Err(e) => {
            // Every error must name the source and print without panicking.
            let msg = e.to_string();
            assert!(
                msg.starts_with(format::IN_MEMORY),
                "error does not name the file: {msg}"
            );
            let _: &FormatError = &e;
            false
        }
    }
}
