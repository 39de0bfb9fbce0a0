//! The subcommands, one module each: they load, call the measurement
//! modules and print (text, or one JSON document with `--json`). `tables`
//! has a directory of its own ([`crate::tables`]).

pub mod accuracy;
pub mod build;
pub mod convert;
pub mod gpu_bench;
pub mod info;
pub mod iso;
pub mod job;
pub mod render;
mod text;
