//! Compact tet layouts (being written).
pub mod baseline32;
pub mod tet16;
pub mod tet20;
pub mod tet32;
pub mod tet80;
