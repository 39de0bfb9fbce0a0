//! What the program writes for its reader: lines and JSON documents on
//! stdout, and errors as one line.
//!
//! Every stdout write goes through [`write_line`] (the [`outln!`] macro)
//! or [`print_json`]. When the reader has gone (`tet-bench info … | head
//! -2`), a write fails with a broken pipe; that becomes [`StdoutClosed`],
//! which `main` turns into a quiet, successful exit, as Unix tools do —
//! never a panic.

use std::fmt;
use std::io::{ErrorKind, Write};

/// Stdout was closed by its reader: nothing more can be said, and nothing
/// went wrong.
#[derive(Debug, thiserror::Error)]
#[error("stdout was closed by its reader")]
pub struct StdoutClosed;

/// Writes one line to stdout. A closed stdout is [`StdoutClosed`]; any
/// other write error is reported as such.
pub fn write_line(args: fmt::Arguments<'_>) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    let written = out.write_fmt(args).and_then(|()| out.write_all(b"\n"));
    match written {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => Err(StdoutClosed.into()),
        Err(e) => Err(anyhow::Error::new(e).context("cannot write to stdout")),
    }
}

/// `println!` for the program's output: the same arguments, through
/// [`write_line`], evaluating to its `Result`.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::output::write_line(format_args!($($arg)*))
    };
}
pub(crate) use outln;

/// Writes `doc` as one pretty-printed JSON document (the `--json` output).
pub fn print_json<T: serde::Serialize>(doc: &T) -> anyhow::Result<()> {
    write_line(format_args!("{}", serde_json::to_string_pretty(doc)?))
}

/// True when `e` (or one of its causes) says stdout was closed.
pub fn is_stdout_closed(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.is::<StdoutClosed>())
}

/// The error and its causes on one line; a cause whose text the message
/// already contains (many of our errors quote their source) is not repeated.
pub fn error_chain(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let c = cause.to_string();
        if !text.contains(&c) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&c);
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_stdout_is_recognised_through_context() {
        let e = anyhow::Error::new(StdoutClosed).context("printing the tables");
        assert!(is_stdout_closed(&e));
        let other = anyhow::anyhow!("stdout was closed by its reader (a message, not the error)");
        assert!(!is_stdout_closed(&other));
    }

    #[test]
    fn error_chain_skips_causes_already_quoted() {
        let e = anyhow::anyhow!("disk full").context("cannot write a.tmesh: disk full");
        assert_eq!(error_chain(&e), "cannot write a.tmesh: disk full");
        let e = anyhow::anyhow!("disk full").context("cannot write a.tmesh");
        assert_eq!(error_chain(&e), "cannot write a.tmesh: disk full");
    }
}
