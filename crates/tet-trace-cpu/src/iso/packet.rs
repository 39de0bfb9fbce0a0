//! Packet traversal (placeholder, filled below).
