//! The resident memory of a whole process tree — a build's own process
//! and every TetGen worker it starts — because a memory limit on one
//! machine is a limit on all of them together, not on each worker alone.
//!
//! Linux only (`/proc`): elsewhere every reading is `None`.
//!
//! * [`resident_kib`]: one process's resident set (`VmRSS`) now.
//! * [`TreeSampler`]: the largest sum of `VmRSS` over a process and all
//!   its descendants, sampled every few milliseconds on a thread of its
//!   own. A sampled peak can miss a spike shorter than the interval; the
//!   builds it watches grow their memory over hundreds of milliseconds.
//!
//! A child between `clone` and `exec` still shares its parent's address
//! space (`posix_spawn` clones with `CLONE_VM`), so its `VmRSS` reads the
//! parent's pages a second time; such a child (its parent's command line)
//! is not counted. A zombie has no memory to read and is not counted
//! either.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

/// The interval at which [`TreeSampler::start`] samples.
pub const SAMPLE_INTERVAL: Duration = Duration::from_millis(2);

/// The resident set (`VmRSS`) of process `pid` now, KiB; `None` where
/// `/proc` is unavailable, the process is gone or is a zombie.
pub fn resident_kib(pid: u32) -> Option<u64> {
    crate::tetgen::worker::status_kib(&pid.to_string(), "VmRSS:")
}

/// The resident set (`VmRSS`) of this process now, bytes (0 without
/// `/proc`).
pub fn own_resident_bytes() -> u64 {
    resident_kib(std::process::id()).map_or(0, |k| k * 1024)
}

/// The children of `pid` (of all its threads).
fn children(pid: u32) -> Vec<u32> {
    let mut out = Vec::new();
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return out;
    };
    for task in tasks.flatten() {
        let path: PathBuf = task.path().join("children");
        if let Ok(text) = std::fs::read_to_string(path) {
            out.extend(
                text.split_whitespace()
                    .filter_map(|c| c.parse::<u32>().ok()),
            );
        }
    }
    out
}

/// The sum of `VmRSS` over `root` and its descendants now, KiB; `None`
/// when `root` cannot be read.
pub fn tree_resident_kib(root: u32) -> Option<u64> {
    let cmdline = |pid: u32| std::fs::read(format!("/proc/{pid}/cmdline")).ok();
    let mut total = resident_kib(root)?;
    let mut stack = vec![(root, cmdline(root))];
    while let Some((pid, args)) = stack.pop() {
        for child in children(pid) {
            // The command line first: when it is still the parent's, the
            // child has not exec'd and its memory is the parent's (read
            // after, it is that or the fresh program's, a few pages).
            let child_args = cmdline(child);
            if child_args.is_none() || child_args == args {
                continue;
            }
            let Some(rss) = resident_kib(child) else {
                continue;
            };
            total += rss;
            stack.push((child, child_args));
        }
    }
    Some(total)
}

/// Samples the resident memory of a process tree on its own thread until
/// [`TreeSampler::finish`].
pub struct TreeSampler {
    stop: Arc<AtomicBool>,
    handle: JoinHandle<Option<u64>>,
}

impl TreeSampler {
    /// Starts sampling the tree of `root` every [`SAMPLE_INTERVAL`].
    pub fn start(root: u32) -> TreeSampler {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let handle = std::thread::spawn(move || {
            let mut peak: Option<u64> = None;
            loop {
                // One last sample after the stop request.
                let last = flag.load(Ordering::Acquire);
                if let Some(kib) = tree_resident_kib(root) {
                    peak = Some(peak.map_or(kib, |p| p.max(kib)));
                }
                if last {
                    break peak;
                }
                std::thread::sleep(SAMPLE_INTERVAL);
            }
        });
        TreeSampler { stop, handle }
    }

    /// Starts sampling this process's tree.
    pub fn start_own() -> TreeSampler {
        TreeSampler::start(std::process::id())
    }

    /// Stops sampling; the largest sum of resident memory seen, KiB
    /// (`None` without `/proc`).
    pub fn finish(self) -> Option<u64> {
        self.stop.store(true, Ordering::Release);
        self.handle.join().ok().flatten()
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    #[test]
    fn a_child_holding_memory_is_counted_with_its_parent() {
        // A child that touches 64 MiB and waits: the tree's resident
        // memory must include it, this process's own must not.
        let mut child = std::process::Command::new("sh")
            .arg("-c")
            .arg("head -c 67108864 /dev/zero | tail -c 67108864 > /dev/null; sleep 2")
            .spawn()
            .expect("sh");
        let sampler = TreeSampler::start_own();
        let own = own_resident_bytes() / 1024;
        std::thread::sleep(Duration::from_millis(1500));
        let peak = sampler.finish().expect("/proc");
        let _ = child.kill();
        let _ = child.wait();
        // `tail -c N` holds the last N bytes in memory.
        assert!(
            peak >= own + 60 * 1024,
            "tree peak {peak} KiB, own {own} KiB"
        );
    }
}
