// Body of the `tetgen_files` fuzz target: arbitrary `.node`, `.ele`, `.face`
// and `.neigh` text given to `tet_build::tetgen_files::read` and
// `to_tet_mesh`.
//
// Input layout: byte 0 says which optional files exist (bit 0: `.face`,
// bit 1: `.neigh`); the rest is split at NUL bytes into the texts of
// `.node`, `.ele`, `.face`, `.neigh` (missing parts are empty). The files are
// written to a per-thread scratch directory (the reader takes a path).
//
// Property: `read` returns a typed `FilesError` naming the file, or files
// whose every index is in range; such files survive `write` + `read`
// unchanged; `to_tet_mesh` returns a typed error or a mesh that validates,
// has the files' tets (up to orientation) and survives
// `from_tet_mesh` + `to_tet_mesh` unchanged. Never a panic.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use tet_build::tetgen_files::{self, TetgenFiles};

/// A per-thread scratch directory and the `base` path inside it.
fn scratch(name: &str) -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    thread_local! {
        static DIR: RefCell<Option<PathBuf>> = const { RefCell::new(None) };
    }
    DIR.with(|d| {
        let mut d = d.borrow_mut();
        let dir = d.get_or_insert_with(|| {
            let dir = std::env::temp_dir().join(format!(
                "tetrays-fuzz-tetgen-{}-{}",
                std::process::id(),
                NEXT.fetch_add(1, Ordering::Relaxed)
            ));
            std::fs::create_dir_all(&dir).expect("create the scratch directory");
            dir
        });
        dir.join(name)
    })
}

fn with_ext(base: &Path, ext: &str) -> PathBuf {
    let mut s = base.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Splits fuzz bytes into the four file texts and which optional files exist.
pub fn split(data: &[u8]) -> ([&[u8]; 4], bool, bool) {
    let (flags, rest) = data.split_first().map_or((0, &[][..]), |(f, r)| (*f, r));
    let mut parts = rest.splitn(4, |&b| b == 0);
    let texts = [(); 4].map(|_| parts.next().unwrap_or(&[]));
    (texts, flags & 1 == 1, flags & 2 == 2)
}

/// Joins four file texts into one fuzz input (the inverse of [`split`]).
pub fn join(node: &str, ele: &str, face: Option<&str>, neigh: Option<&str>) -> Vec<u8> {
    let mut out = vec![face.is_some() as u8 | (neigh.is_some() as u8) << 1];
    for (i, t) in [Some(node), Some(ele), face, neigh].into_iter().enumerate() {
        if i > 0 {
            out.push(0);
        }
        out.extend_from_slice(t.unwrap_or("").as_bytes());
    }
    out
}

/// Runs the property on `data`; returns whether a mesh was built.
pub fn check(data: &[u8]) -> bool {
    let ([node, ele, face, neigh], has_face, has_neigh) = split(data);
    let base = scratch("in");
    let write = |ext: &str, text: Option<&[u8]>| {
        let p = with_ext(&base, ext);
        match text {
            Some(t) => std::fs::write(&p, t).expect("write scratch file"),
            None => {
                let _ = std::fs::remove_file(&p);
            }
        }
    };
    write("node", Some(node));
    write("ele", Some(ele));
    write("face", has_face.then_some(face));
    write("neigh", has_neigh.then_some(neigh));
    match tetgen_files::read(&base) {
        Ok(files) => {
            check_files(&files, has_face, has_neigh);
            check_write_read(&files);
            check_mesh(&files, &base)
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(
                msg.contains(&*base.to_string_lossy()),
                "error does not name the file: {msg}"
            );
            false
        }
    }
}

fn check_files(files: &TetgenFiles, has_face: bool, has_neigh: bool) {
    let n = files.points.len();
    assert!(files.points.iter().flatten().all(|x| x.is_finite()));
    assert!(files.tets.iter().flatten().all(|&v| (v as usize) < n));
    assert!(files.faces.iter().flatten().all(|&v| (v as usize) < n));
    if let Some(m) = &files.face_markers {
        assert!(has_face);
        assert_eq!(m.len(), files.faces.len());
    }
    if !has_face {
        assert!(files.faces.is_empty() && files.face_markers.is_none());
    }
    assert_eq!(files.neighbors.is_some(), has_neigh);
    if let Some(rows) = &files.neighbors {
        assert_eq!(rows.len(), files.tets.len());
        let nt = files.tets.len() as i64;
        assert!(
            rows.iter()
                .flatten()
                .all(|&x| x == -1 || (0..nt).contains(&i64::from(x)))
        );
    }
}

fn check_write_read(files: &TetgenFiles) {
    let base = scratch("out");
    for ext in ["node", "ele", "face", "neigh"] {
        let _ = std::fs::remove_file(with_ext(&base, ext));
    }
    tetgen_files::write(&base, files).expect("write scratch files");
    let again = tetgen_files::read(&base).expect("written files read back");
    // Bitwise on the coordinates (`-0.0` must survive).
    let bits = |f: &TetgenFiles| -> Vec<[u64; 3]> {
        f.points.iter().map(|p| p.map(f64::to_bits)).collect()
    };
    assert_eq!(bits(&again), bits(files));
    assert_eq!(again, *files);
}

fn check_mesh(files: &TetgenFiles, base: &Path) -> bool {
    match tetgen_files::to_tet_mesh(files, base, None) {
        Ok(mesh) => {
            if let Err(e) = mesh.validate() {
                panic!("to_tet_mesh returned an invalid mesh: {e}");
            }
            assert_eq!(mesh.tets.len(), files.tets.len());
            for (m, f) in mesh.tets.iter().zip(&files.tets) {
                let (mut a, mut b) = (*m, *f);
                a.sort_unstable();
                b.sort_unstable();
                assert_eq!(a, b, "tet changed its vertices");
            }
            let markers = files.face_markers.as_deref().unwrap_or(&[]);
            assert_eq!(
                mesh.constrained.len(),
                markers.iter().filter(|&&m| m > 0).count()
            );
            let back = tetgen_files::from_tet_mesh(&mesh);
            let again = tetgen_files::to_tet_mesh(&back, base, Some(mesh.triangle_count))
                .expect("an exported mesh imports");
            assert!(
                again == mesh,
                "from_tet_mesh/to_tet_mesh round trip differs"
            );
            true
        }
        Err(e) => {
            let _ = e.to_string();
            false
        }
    }
}
