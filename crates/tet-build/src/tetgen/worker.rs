//! Isolated TetGen runs: a worker process reads one request on stdin, runs
//! TetGen in process, and writes one reply on stdout.
//!
//! Hosts: the `tet-build-worker` binary (used by this crate's tests through
//! `CARGO_BIN_EXE_tet-build-worker`) and any binary that re-executes itself
//! with a hidden subcommand calling [`serve_stdio`] (e.g. `tet-bench`).
//! [`run_worker`] is the parent side: it spawns the command, streams the
//! request, reads the reply and kills the child at the time limit.
//!
//! Hosting the worker in another binary (e.g. `tet-bench`):
//!
//! ```no_run
//! use std::time::Duration;
//! use tet_build::tetgen::{Isolation, WorkerCommand};
//! // First thing in main(): the hidden subcommand serves one request.
//! if std::env::args().nth(1).as_deref() == Some("__tetgen-worker") {
//!     std::process::exit(tet_build::tetgen::worker::serve_stdio());
//! }
//! // Elsewhere: run TetGen in a re-executed copy of this binary.
//! let isolation = Isolation::Worker(WorkerCommand {
//!     program: std::env::current_exe().unwrap(),
//!     args: vec!["__tetgen-worker".into()],
//!     timeout: Some(Duration::from_secs(600)),
//! });
//! ```
//!
//! Wire format (little-endian).
//!
//! * Request: `b"TETREQ01"`, switches (u32 length and UTF-8), points (u32
//!   count, 3 f64 each), triangles (u32 count, 3 u32 each), markers (one i32
//!   per triangle).
//! * Reply: `b"TETRES02"`, status i32 (0 = ok, else a shim/TetGen code);
//!   on success points, tets (u32 count, 4 u32 each), a neighbours flag (u8)
//!   with 4 i32 per tet, faces (u32 count, 3 u32 each), one i32 marker per
//!   face and a face-tets flag (u8) with 2 i32 per face; always followed by TetGen seconds (f64) and the worker's peak
//!   memory in KiB (u64, 0 when unknown).
//!
//! TetGen prints its diagnostics with `printf`; [`serve_stdio`] first points
//! C stdout at stderr so they cannot corrupt the reply.

use std::io::{self, BufReader, BufWriter, Read, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::check::check_input;
use super::error::TetgenError;
use super::in_process::run_in_process;
use super::types::{Optimization, TetgenInput, TetgenOptions, TetgenOutput, WorkerCommand};

const REQUEST_MAGIC: &[u8; 8] = b"TETREQ01";
const REPLY_MAGIC: &[u8; 8] = b"TETRES02";
/// Status of a reply the worker could not decode a request for.
const STATUS_BAD_REQUEST: i32 = -100;

/// Peak resident set size of this process (`VmHWM` in `/proc/self/status`), KiB.
/// `None` where `/proc` is unavailable.
pub fn peak_memory_kib() -> Option<u64> {
    status_kib("self", "VmHWM:")
}

/// Field `key` (e.g. `"VmRSS:"`) of `/proc/PROCESS/status` in KiB, for
/// `PROCESS` a pid or `self`; `None` where `/proc` is unavailable, the
/// process is gone or lacks the field (a zombie).
pub fn status_kib(process: &str, key: &str) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{process}/status")).ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
}

/// Worker entry point: points C stdout at stderr, serves one request from
/// stdin to the original stdout, and returns the process exit code (0 when a
/// reply was written, even if the reply is a TetGen error).
pub fn serve_stdio() -> i32 {
    // SAFETY: plain POSIX dup/dup2 on fds 1 and 2, performed before any
    // other thread writes to stdout.
    let fd = unsafe { super::ffi::tetshim_redirect_stdout() };
    let result = if fd >= 0 {
        use std::os::fd::FromRawFd;
        // SAFETY: `fd` is a fresh duplicate of the original stdout, owned
        // exclusively by this File from here on.
        let out = unsafe { std::fs::File::from_raw_fd(fd) };
        serve(io::stdin().lock(), out)
    } else {
        serve(io::stdin().lock(), io::stdout().lock())
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("tet-build worker: {e}");
            1
        }
    }
}

/// Reads one request from `input`, runs TetGen in this process, writes the
/// reply to `output`. I/O errors are returned; TetGen errors travel in the reply.
pub fn serve<R: Read, W: Write>(input: R, output: W) -> io::Result<()> {
    let mut r = BufReader::new(input);
    let mut w = BufWriter::new(output);
    w.write_all(REPLY_MAGIC)?;
    let request = read_request(&mut r);
    let result = match request {
        Err(e) => Err(Err(e)),
        Ok((input, switches_options)) => {
            match check_input(&input).and_then(|_| run_in_process(&input, &switches_options)) {
                Ok(out) => Ok(out),
                Err(e) => Err(Ok(e)),
            }
        }
    };
    let peak = peak_memory_kib().unwrap_or(0);
    match result {
        Ok(out) => {
            put_i32(&mut w, 0)?;
            put_u32(&mut w, out.points.len() as u32)?;
            for p in &out.points {
                for c in p {
                    put_f64(&mut w, *c)?;
                }
            }
            put_u32(&mut w, out.tets.len() as u32)?;
            for t in &out.tets {
                for v in t {
                    put_u32(&mut w, *v)?;
                }
            }
            match &out.neighbors {
                Some(n) => {
                    w.write_all(&[1])?;
                    for t in n {
                        for v in t {
                            put_i32(&mut w, *v)?;
                        }
                    }
                }
                None => w.write_all(&[0])?,
            }
            put_u32(&mut w, out.faces.len() as u32)?;
            for f in &out.faces {
                for v in f {
                    put_u32(&mut w, *v)?;
                }
            }
            for m in &out.face_markers {
                put_i32(&mut w, *m)?;
            }
            match &out.face_tets {
                Some(ft) => {
                    w.write_all(&[1])?;
                    for f in ft {
                        put_i32(&mut w, f[0])?;
                        put_i32(&mut w, f[1])?;
                    }
                }
                None => w.write_all(&[0])?,
            }
            put_f64(&mut w, out.seconds)?;
        }
        Err(Ok(e)) => {
            // Input errors found by check_input in the worker travel as a
            // message; TetGen codes as codes.
            match e.code() {
                Some(c) => {
                    put_i32(&mut w, c)?;
                }
                None => {
                    put_i32(&mut w, STATUS_BAD_REQUEST)?;
                    put_str(&mut w, &e.to_string())?;
                }
            }
            put_f64(&mut w, 0.0)?;
        }
        Err(Err(e)) => {
            put_i32(&mut w, STATUS_BAD_REQUEST)?;
            put_str(&mut w, &format!("bad request: {e}"))?;
            put_f64(&mut w, 0.0)?;
        }
    }
    put_u64(&mut w, peak)?;
    w.flush()
}

/// Options travel as the switch string; the worker rebuilds them from it.
fn read_request<R: Read>(r: &mut R) -> io::Result<(TetgenInput, TetgenOptions)> {
    let mut magic = [0u8; 8];
    r.read_exact(&mut magic)?;
    if &magic != REQUEST_MAGIC {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            "bad request magic",
        ));
    }
    let switches = get_str(r)?;
    let options = parse_switches(&switches)
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidData, "bad switches"))?;
    let np = get_u32(r)? as usize;
    let mut points = Vec::with_capacity(np.min(1 << 16));
    for _ in 0..np {
        points.push([get_f64(r)?, get_f64(r)?, get_f64(r)?]);
    }
    let nt = get_u32(r)? as usize;
    let mut triangles = Vec::with_capacity(nt.min(1 << 16));
    for _ in 0..nt {
        triangles.push([get_u32(r)?, get_u32(r)?, get_u32(r)?]);
    }
    let mut markers = Vec::with_capacity(nt.min(1 << 16));
    for _ in 0..nt {
        markers.push(get_i32(r)?);
    }
    Ok((
        TetgenInput {
            points,
            triangles,
            markers,
        },
        options,
    ))
}

/// Inverse of [`TetgenOptions::switches`].
fn parse_switches(s: &str) -> Option<TetgenOptions> {
    let mut o = TetgenOptions {
        preserve_surface: false,
        keep_convex_hull: false,
        ..TetgenOptions::default()
    };
    let b = s.as_bytes();
    let mut i = 0;
    let number = |i: &mut usize| -> &str {
        let start = *i;
        while *i < b.len() && (b[*i].is_ascii_digit() || b"+-.eE".contains(&b[*i])) {
            *i += 1;
        }
        &s[start..*i]
    };
    while i < b.len() {
        let c = b[i];
        i += 1;
        match c {
            b'p' | b'z' | b'Q' => {}
            b'Y' => {
                o.preserve_surface = true;
                if b[i..].starts_with(b"/2") {
                    o.steiner_off_surface = true;
                    i += 2;
                }
            }
            b'c' => o.keep_convex_hull = true,
            b'n' if o.neighbors => o.face_tets = true,
            b'n' => o.neighbors = true,
            b'q' => {
                let q: f64 = number(&mut i).parse().ok()?;
                if b.get(i) == Some(&b'/') {
                    i += 1;
                    o.min_dihedral = Some(number(&mut i).parse().ok()?);
                    o.quality = (q != super::types::NO_RATIO).then_some(q);
                } else {
                    o.quality = Some(q);
                }
            }
            b'S' => o.max_steiner = Some(number(&mut i).parse().ok()?),
            b'T' => o.coplanar_tolerance = Some(number(&mut i).parse().ok()?),
            b'O' => {
                let digit = |i: &mut usize| {
                    let d = b.get(*i).filter(|c| c.is_ascii_digit())?;
                    *i += 1;
                    Some(d - b'0')
                };
                let level = digit(&mut i)?;
                (b.get(i) == Some(&b'/')).then_some(())?;
                i += 1;
                let scheme = digit(&mut i)?;
                o.optimization = Some(Optimization { level, scheme });
            }
            b'o' => {
                (b.get(i) == Some(&b'/')).then_some(())?;
                i += 1;
                o.max_dihedral = Some(number(&mut i).parse().ok()?);
            }
            _ => return None,
        }
    }
    (o.switches() == s).then_some(o)
}

/// Runs TetGen in a child process (input already checked by the caller).
///
/// With `TET_WORKER_KEEP=DIR` in the environment, a request that runs past
/// its time limit is kept as `DIR/timeout-PID.req`, and one whose worker
/// dies (a crash in TetGen) as `DIR/crash-PID.req`, so that the run can be
/// replayed on its own (`tet-bench tetgen-worker < FILE`) and reported.
pub fn run_worker(
    cmd: &WorkerCommand,
    input: &TetgenInput,
    options: &TetgenOptions,
) -> Result<TetgenOutput, TetgenError> {
    let io_err = |what: &str, e: io::Error| TetgenError::WorkerIo(format!("{what}: {e}"));
    let mut child = Command::new(&cmd.program)
        .args(&cmd.args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| io_err(&format!("spawn {}", cmd.program.display()), e))?;
    let start = Instant::now();
    let mut stdin = child.stdin.take().expect("piped stdin");
    let mut stdout = child.stdout.take().expect("piped stdout");
    let mut stderr = child.stderr.take().expect("piped stderr");
    let switches = options.switches();
    let request = encode_request(input, &switches);
    let keep = std::env::var_os("TET_WORKER_KEEP").map(|d| (d, request.clone()));
    // Keeps the request as `DIR/{what}-PID.req` (see above).
    let keep_as = |what: &str, pid: u32| {
        if let Some((dir, request)) = &keep {
            let path = std::path::Path::new(dir).join(format!("{what}-{pid}.req"));
            let _ = std::fs::write(&path, request);
        }
    };
    let writer = std::thread::spawn(move || -> io::Result<()> {
        stdin.write_all(&request)?;
        stdin.flush()
    });
    let reader = std::thread::spawn(move || -> io::Result<Vec<u8>> {
        let mut buf = Vec::new();
        stdout.read_to_end(&mut buf)?;
        Ok(buf)
    });
    let err_reader = std::thread::spawn(move || -> Vec<u8> {
        // Keep only the tail: TetGen can be chatty.
        let mut tail = Vec::new();
        let mut chunk = [0u8; 4096];
        while let Ok(n) = stderr.read(&mut chunk) {
            if n == 0 {
                break;
            }
            tail.extend_from_slice(&chunk[..n]);
            if tail.len() > 8192 {
                tail.drain(..tail.len() - 4096);
            }
        }
        tail
    });
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) => {}
            Err(e) => return Err(io_err("wait", e)),
        }
        if let Some(limit) = cmd.timeout
            && start.elapsed() > limit
        {
            let _ = child.kill();
            let _ = child.wait();
            let _ = writer.join();
            let _ = reader.join();
            let _ = err_reader.join();
            keep_as("timeout", child.id());
            return Err(TetgenError::Timeout {
                seconds: limit.as_secs_f64(),
            });
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    // A write error just means the child exited early; the reply says why.
    let _ = writer.join();
    let reply = reader
        .join()
        .map_err(|_| TetgenError::WorkerIo("reader thread panicked".into()))?
        .map_err(|e| io_err("read reply", e))?;
    let stderr_tail = String::from_utf8_lossy(&err_reader.join().unwrap_or_default()).into_owned();
    if !status.success() || reply.len() < REPLY_MAGIC.len() {
        keep_as("crash", child.id());
        return Err(TetgenError::WorkerDied {
            status: status.to_string(),
            stderr: stderr_tail
                .trim()
                .chars()
                .rev()
                .take(1000)
                .collect::<String>()
                .chars()
                .rev()
                .collect(),
        });
    }
    decode_reply(&reply, &switches)
}

fn encode_request(input: &TetgenInput, switches: &str) -> Vec<u8> {
    let mut w = Vec::with_capacity(32 + input.points.len() * 24 + input.triangles.len() * 16);
    w.extend_from_slice(REQUEST_MAGIC);
    // Writing to a Vec cannot fail.
    let _ = put_str(&mut w, switches);
    let _ = put_u32(&mut w, input.points.len() as u32);
    for p in &input.points {
        for c in p {
            let _ = put_f64(&mut w, *c);
        }
    }
    let _ = put_u32(&mut w, input.triangles.len() as u32);
    for t in &input.triangles {
        for v in t {
            let _ = put_u32(&mut w, *v);
        }
    }
    for m in &input.markers {
        let _ = put_i32(&mut w, *m);
    }
    w
}

fn decode_reply(reply: &[u8], switches: &str) -> Result<TetgenOutput, TetgenError> {
    let proto = |e: io::Error| TetgenError::Protocol(format!("truncated reply: {e}"));
    let mut r = reply;
    let mut magic = [0u8; 8];
    r.read_exact(&mut magic).map_err(proto)?;
    if &magic != REPLY_MAGIC {
        return Err(TetgenError::Protocol("bad reply magic".into()));
    }
    let status = get_i32(&mut r).map_err(proto)?;
    if status != 0 {
        let message = if status == STATUS_BAD_REQUEST {
            Some(get_str(&mut r).map_err(proto)?)
        } else {
            None
        };
        return Err(match message {
            Some(m) => TetgenError::Protocol(m),
            None => TetgenError::from_code(status, switches),
        });
    }
    let np = get_u32(&mut r).map_err(proto)? as usize;
    let check_len = |r: &[u8], n: usize, each: usize| {
        if r.len() < n.saturating_mul(each) {
            Err(TetgenError::Protocol("truncated reply".into()))
        } else {
            Ok(())
        }
    };
    check_len(r, np, 24)?;
    let mut points = Vec::with_capacity(np);
    for _ in 0..np {
        points.push([
            get_f64(&mut r).map_err(proto)?,
            get_f64(&mut r).map_err(proto)?,
            get_f64(&mut r).map_err(proto)?,
        ]);
    }
    let index = |v: u32| {
        if (v as usize) < np {
            Ok(v)
        } else {
            Err(TetgenError::Protocol(format!("vertex id {v} out of range")))
        }
    };
    let nt = get_u32(&mut r).map_err(proto)? as usize;
    check_len(r, nt, 16)?;
    let mut tets = Vec::with_capacity(nt);
    for _ in 0..nt {
        let mut t = [0u32; 4];
        for v in &mut t {
            *v = index(get_u32(&mut r).map_err(proto)?)?;
        }
        tets.push(t);
    }
    let mut flag = [0u8; 1];
    r.read_exact(&mut flag).map_err(proto)?;
    let neighbors = if flag[0] == 1 {
        check_len(r, nt, 16)?;
        let mut n = Vec::with_capacity(nt);
        for _ in 0..nt {
            n.push([
                get_i32(&mut r).map_err(proto)?,
                get_i32(&mut r).map_err(proto)?,
                get_i32(&mut r).map_err(proto)?,
                get_i32(&mut r).map_err(proto)?,
            ]);
        }
        Some(n)
    } else {
        None
    };
    let nf = get_u32(&mut r).map_err(proto)? as usize;
    check_len(r, nf, 16)?;
    let mut faces = Vec::with_capacity(nf);
    for _ in 0..nf {
        faces.push([
            index(get_u32(&mut r).map_err(proto)?)?,
            index(get_u32(&mut r).map_err(proto)?)?,
            index(get_u32(&mut r).map_err(proto)?)?,
        ]);
    }
    let mut face_markers = Vec::with_capacity(nf);
    for _ in 0..nf {
        face_markers.push(get_i32(&mut r).map_err(proto)?);
    }
    r.read_exact(&mut flag).map_err(proto)?;
    let face_tets = if flag[0] == 1 {
        // Raw values, as in process (see `TetgenOutput::face_tets`).
        check_len(r, nf, 8)?;
        let mut v = Vec::with_capacity(nf);
        for _ in 0..nf {
            v.push([
                get_i32(&mut r).map_err(proto)?,
                get_i32(&mut r).map_err(proto)?,
            ]);
        }
        Some(v)
    } else {
        None
    };
    let seconds = get_f64(&mut r).map_err(proto)?;
    let peak = get_u64(&mut r).map_err(proto)?;
    Ok(TetgenOutput {
        points,
        tets,
        neighbors,
        faces,
        face_markers,
        face_tets,
        worker_peak_kib: (peak > 0).then_some(peak),
        seconds,
    })
}

fn put_u32<W: Write>(w: &mut W, v: u32) -> io::Result<()> {
    w.write_all(&v.to_le_bytes())
}
fn put_i32<W: Write>(w: &mut W, v: i32) -> io::Result<()> {
    w.write_all(&v.to_le_bytes())
}
fn put_u64<W: Write>(w: &mut W, v: u64) -> io::Result<()> {
    w.write_all(&v.to_le_bytes())
}
fn put_f64<W: Write>(w: &mut W, v: f64) -> io::Result<()> {
    w.write_all(&v.to_le_bytes())
}
fn put_str<W: Write>(w: &mut W, s: &str) -> io::Result<()> {
    put_u32(w, s.len() as u32)?;
    w.write_all(s.as_bytes())
}
fn get_u32<R: Read>(r: &mut R) -> io::Result<u32> {
    let mut b = [0u8; 4];
    r.read_exact(&mut b)?;
    Ok(u32::from_le_bytes(b))
}
fn get_i32<R: Read>(r: &mut R) -> io::Result<i32> {
    let mut b = [0u8; 4];
    r.read_exact(&mut b)?;
    Ok(i32::from_le_bytes(b))
}
fn get_u64<R: Read>(r: &mut R) -> io::Result<u64> {
    let mut b = [0u8; 8];
    r.read_exact(&mut b)?;
    Ok(u64::from_le_bytes(b))
}
fn get_f64<R: Read>(r: &mut R) -> io::Result<f64> {
    let mut b = [0u8; 8];
    r.read_exact(&mut b)?;
    Ok(f64::from_le_bytes(b))
}
fn get_str<R: Read>(r: &mut R) -> io::Result<String> {
    let n = get_u32(r)? as usize;
    if n > 1 << 20 {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            "string too long",
        ));
    }
    let mut b = vec![0u8; n];
    r.read_exact(&mut b)?;
    String::from_utf8(b).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn switches_round_trip() {
        let cases = [
            TetgenOptions::default(),
            TetgenOptions {
                quality: Some(1.5),
                max_steiner: Some(1000),
                coplanar_tolerance: Some(1e-9),
                neighbors: true,
                face_tets: false,
                keep_convex_hull: false,
                preserve_surface: false,
                steiner_off_surface: false,
                optimization: Some(Optimization {
                    level: 7,
                    scheme: 3,
                }),
                max_dihedral: Some(140.5),
                min_dihedral: None,
            },
            TetgenOptions {
                quality: Some(4.0),
                min_dihedral: Some(8.5),
                ..TetgenOptions::default()
            },
            TetgenOptions {
                min_dihedral: Some(10.0),
                ..TetgenOptions::default()
            },
            TetgenOptions {
                neighbors: true,
                face_tets: true,
                ..TetgenOptions::default()
            },
            TetgenOptions {
                steiner_off_surface: true,
                coplanar_tolerance: Some(1e-12),
                ..TetgenOptions::default()
            },
        ];
        for o in cases {
            assert_eq!(parse_switches(&o.switches()), Some(o));
        }
        assert_eq!(parse_switches("pYczQx"), None);
        assert_eq!(parse_switches("pY/3czQ"), None);
        assert_eq!(parse_switches("pYczO7zQ"), None);
    }

    #[test]
    fn reply_decodes_what_serve_encodes_for_errors() {
        // An empty PLC is rejected by check_input inside the worker: the
        // reply carries the message, not a TetGen code.
        let req = encode_request(&TetgenInput::default(), "pYczQ");
        let mut reply = Vec::new();
        serve(&req[..], &mut reply).unwrap();
        match decode_reply(&reply, "pYczQ") {
            Err(TetgenError::Protocol(m)) => assert!(m.contains("empty input"), "{m}"),
            other => panic!("unexpected {other:?}"),
        }
    }
}
