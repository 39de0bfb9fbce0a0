//! The host-side start of batch rays: the CPU walk's exact start logic,
//! uploaded as a start record so that the GPU starts exactly where the CPU
//! starts.

use tet_core::{FACE_VERTICES, Link, NO_TET, TetMesh};
use tet_trace_cpu::walk::start_exit_face;
use tet_trace_cpu::{DuffF32, Ray, Start};

use crate::layout::GpuLayout;
use crate::records::{ST_INVALID, ST_LOST, START_DONE, START_ENTER, START_EXIT, StartRec};

/// Host-side start of one batch ray: the CPU walk's exact start logic.
pub(crate) fn start_record(mesh: &TetMesh, layout: GpuLayout, ray: &Ray, start: Start) -> StartRec {
    let done = |status| StartRec {
        mode: START_DONE,
        ids: [0; 3],
        tet: NO_TET,
        link: status,
        visited: 0,
        next: 0,
    };
    if !ray.is_valid() {
        return done(ST_INVALID);
    }
    if layout == GpuLayout::Tet80 {
        return start_record_tet80(mesh, ray, start);
    }
    match start {
        Start::Tet(t) => {
            if t as usize >= mesh.tets.len() {
                return done(ST_LOST);
            }
            match start_exit_face::<DuffF32>(mesh, ray, t) {
                Some((tet, k)) => StartRec {
                    mode: START_EXIT,
                    ids: mesh.face_vertices(tet, k),
                    tet,
                    link: mesh.neighbors[tet as usize][k].0,
                    visited: 1,
                    next: 0,
                },
                None => done(ST_LOST),
            }
        }
        Start::Face { face, tet } => {
            let side = mesh
                .constrained
                .get(face as usize)
                .and_then(|cf| cf.side_of(tet))
                .filter(|_| (tet as usize) < mesh.tets.len());
            let Some(side) = side else {
                return done(ST_LOST);
            };
            let v = mesh.tets[tet as usize];
            let [a, b, c] = FACE_VERTICES[(side.face & 3) as usize];
            StartRec {
                mode: START_ENTER,
                ids: [v[a], v[c], v[b]],
                tet: NO_TET,
                link: Link::constrained(face).0,
                visited: 0,
                next: tet,
            }
        }
        Start::Entry { tet, face } => {
            if !mesh.is_boundary_face(tet, face) {
                return done(ST_LOST);
            }
            let v = mesh.tets[tet as usize];
            let [a, b, c] = FACE_VERTICES[(face & 3) as usize];
            StartRec {
                mode: START_ENTER,
                ids: [v[a], v[c], v[b]],
                tet: NO_TET,
                link: Link::BOUNDARY.0,
                visited: 0,
                next: tet,
            }
        }
    }
}

/// Start of a Tet80 walk, as `Tet80Tracer::trace` (Maria et al.'s
/// Algorithm 2 from an interior origin, the triple-product search from an
/// origin on a face, edge or vertex, then `leave` through the exit face;
/// or entering through a face).
fn start_record_tet80(mesh: &TetMesh, ray: &Ray, start: Start) -> StartRec {
    let rec = |mode, tet, face, visited| StartRec {
        mode,
        ids: [face, 0, 0],
        tet,
        link: 0,
        visited,
        next: 0,
    };
    let done = |status, visited| StartRec {
        link: status,
        ..rec(START_DONE, NO_TET, 0, visited)
    };
    match start {
        Start::Tet(t) if (t as usize) < mesh.tets.len() => {
            match tet_trace_cpu::tet80::start_exit(mesh, ray, t) {
                Some((t, k)) => rec(START_EXIT, t, k as u32, 1),
                None => done(ST_LOST, 1),
            }
        }
        Start::Tet(_) => done(ST_LOST, 0),
        Start::Face { face, tet } => {
            match mesh
                .constrained
                .get(face as usize)
                .and_then(|cf| cf.side_of(tet))
                .filter(|_| (tet as usize) < mesh.tets.len())
            {
                Some(s) => rec(START_ENTER, tet, s.face & 3, 0),
                None => done(ST_LOST, 0),
            }
        }
        Start::Entry { tet, face } if mesh.is_boundary_face(tet, face) => {
            rec(START_ENTER, tet, face as u32, 0)
        }
        Start::Entry { .. } => done(ST_LOST, 0),
    }
}
