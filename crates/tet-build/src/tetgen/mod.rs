//! TetGen through our own C ABI shim (being written).
pub mod ffi;
pub mod worker;
