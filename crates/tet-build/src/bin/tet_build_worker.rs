//! Worker process for isolated TetGen runs: reads one request on stdin and
//! writes one reply on stdout (see `tet_build::tetgen::worker`).

fn main() {
    std::process::exit(tet_build::tetgen::worker::serve_stdio());
}
