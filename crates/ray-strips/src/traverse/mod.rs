//! Traversal (paper §5): prepared rays, the watertight strip-leaf test,
//! single rays and 2×2 packets.

pub(crate) mod packet;
pub(crate) mod prepared;
pub(crate) mod single;
pub(crate) mod triangle;
