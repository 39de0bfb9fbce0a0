//! Runs the `traversal` fuzz body on the stable toolchain.
//!
//! * `run N [SEED]`: N generated inputs (random bytes, 64–255 long), each
//!   caught with `catch_unwind`; prints counts, failure classes (the
//!   assertion and the kernel) and time, and writes the first failing inputs
//!   to `fail<k>.bin` in the current directory.
//! * `diag FILE`: decodes one input (e.g. a libFuzzer artifact) and prints the
//!   mesh, every ray with its start, every kernel's outcome and the f64
//!   brute-force reference hit.
//! * `replay DIR`: runs the body on every file of DIR (a seed corpus or
//!   `fuzz/regressions/traversal`), reporting which fail.

use std::collections::BTreeMap;
use std::time::Instant;

use tet_core::synthetic::SplitMix64;
use tet_trace_cpu::{DuffF32, Start, Tracer, TripleF32, reference};
use tet_trace_cpu::{sctp, tet16, tet20, tet32, tet80};

#[allow(dead_code)]
mod input {
    include!("../../targets_common/input.rs");
}
#[allow(dead_code)]
mod grid {
    include!("../../targets_common/grid.rs");
}
#[allow(dead_code)]
mod traversal {
    include!("../../targets_common/traversal.rs");
}

/// Runs the body on `data`; `Err(message)` when an assertion failed.
fn run_one(data: &[u8]) -> Result<usize, String> {
    std::panic::catch_unwind(|| traversal::check(data)).map_err(|e| {
        e.downcast_ref::<String>()
            .cloned()
            .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default()
    })
}

/// (assertion, kernel) of a failure message `"<assertion>: <kernel>: ..."`.
fn class(msg: &str) -> (String, String) {
    let mut parts = msg.splitn(3, ": ");
    let what = parts.next().unwrap_or("").to_string();
    let kernel = parts.next().unwrap_or("").to_string();
    (what, kernel)
}

fn run(iters: usize, seed: u64) {
    std::panic::set_hook(Box::new(|_| {}));
    let mut rng = SplitMix64(seed);
    let start = Instant::now();
    let (mut traced, mut failures) = (0usize, 0usize);
    let mut classes: BTreeMap<(String, String), usize> = BTreeMap::new();
    let mut buf = Vec::new();
    for i in 0..iters {
        buf.clear();
        buf.extend((0..(64 + i % 192)).map(|_| rng.next_u64() as u8));
        match run_one(&buf) {
            Ok(n) => traced += n,
            Err(msg) => {
                failures += 1;
                *classes.entry(class(&msg)).or_insert(0) += 1;
                if failures <= 5 {
                    eprintln!("input {i}: {}", &msg[..msg.len().min(700)]);
                    std::fs::write(format!("fail{failures}.bin"), &buf).expect("write");
                }
            }
        }
    }
    for ((what, kernel), n) in &classes {
        println!("  {n:7} × {what} ({kernel})");
    }
    println!(
        "traversal: {iters} inputs, {traced} traces, {failures} failing inputs, {:.1} s",
        start.elapsed().as_secs_f64()
    );
}

fn diag(path: &str) {
    let data = std::fs::read(path).expect("read input");
    let mut b = input::Bytes::new(&data);
    let mesh = grid::mesh_from(&mut b);
    let _small_cap = 1 + b.below(8);
    let n = 1 + b.below(8);
    let rays: Vec<_> = (0..n).map(|_| traversal::ray_from(&mesh, &mut b)).collect();
    println!(
        "mesh: {} tets, {} points, {} constrained faces",
        mesh.tets.len(),
        mesh.points.len(),
        mesh.constrained.len()
    );
    let tracers: Vec<Box<dyn Tracer + '_>> = vec![
        Box::new(sctp::SctpTracer::<TripleF32>::new(&mesh).expect("sctp")),
        Box::new(tet32::Tet32Tracer::<DuffF32>::new(&mesh).expect("tet32")),
        Box::new(tet32::Tet32TracerF64::new(&mesh).expect("tet32/f64")),
        Box::new(tet20::Tet20Tracer::<DuffF32>::new(&mesh).expect("tet20")),
        Box::new(tet16::Tet16Tracer::<DuffF32>::new(&mesh).expect("tet16")),
        Box::new(tet80::Tet80Tracer::new(&mesh).expect("tet80")),
    ];
    for (ray, start, exact) in &rays {
        println!("ray {ray:?} from {start:?} (precondition holds: {exact})");
        if let Start::Face { face, .. } = start {
            let cf = mesh.constrained[*face as usize];
            println!(
                "  start face {face}: {cf:?} at {:?}",
                cf.vertices.map(|v| mesh.points[v as usize])
            );
        }
        for t in &tracers {
            println!("  {:>14}: {:?}", t.name(), t.trace(ray, *start));
        }
        if ray.is_valid() {
            println!("  reference: {:?}", reference::closest_hit(&mesh, ray));
        }
    }
    match run_one(&data) {
        Ok(n) => println!("body: ok ({n} traces)"),
        Err(msg) => println!("body: FAILS: {msg}"),
    }
}

fn replay(dir: &str) {
    std::panic::set_hook(Box::new(|_| {}));
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").path())
        .collect();
    entries.sort();
    for path in entries {
        let data = std::fs::read(&path).expect("read");
        match run_one(&data) {
            Ok(n) => println!("ok    {} ({n} traces)", path.display()),
            Err(msg) => println!("FAILS {}: {}", path.display(), &msg[..msg.len().min(300)]),
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(String::as_str) {
        Some("run") => run(
            args.get(2)
                .and_then(|s| s.parse().ok())
                .unwrap_or(1_000_000),
            args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0x7A7A),
        ),
        Some("diag") => diag(&args[2]),
        Some("replay") => replay(&args[2]),
        _ => eprintln!("usage: traversal-stable run [N [SEED]] | diag FILE | replay DIR"),
    }
}
