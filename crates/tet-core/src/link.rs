//! The 32-bit neighbour reference stored in every layout.
//!
//! Aman et al. (2022, §3) store a constrained-face flag in the neighbour
//! field so that the hot traversal loop needs only one load to know whether
//! it must stop. The encoding here:
//!
//! | bits                      | meaning                                          |
//! |---------------------------|--------------------------------------------------|
//! | bit 31 clear, `< 2³¹-1`   | index of the neighbour tet                        |
//! | `0x7FFF_FFFF`             | mesh boundary: nothing beyond, the ray misses     |
//! | bit 31 set                | constrained face; bits 0..31 index the face table |
//!
//! The tet on the far side of a constrained face is kept in the cold
//! constrained-face table ([`crate::ConstrainedFace`]), which secondary rays
//! read to restart on the other side.

use bytemuck::{Pod, Zeroable};

/// Exclusive upper bound on the number of tets (and of constrained faces) a
/// mesh may hold: indices must fit in 31 bits and `0x7FFF_FFFF` is reserved.
pub const MAX_TETS: u32 = 0x7FFF_FFFF;

/// Neighbour reference across one face of a tet. See the module docs.
#[repr(transparent)]
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Pod, Zeroable)]
pub struct Link(pub u32);

/// Decoded form of a [`Link`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LinkKind {
    /// The face is shared with this tet.
    Tet(u32),
    /// The face is on the mesh boundary (not a scene triangle).
    Boundary,
    /// The face lies on a scene triangle; the value indexes the constrained-face table.
    Constrained(u32),
}

impl Link {
    /// Flag bit marking a constrained face.
    pub const CONSTRAINED_BIT: u32 = 1 << 31;
    /// The mesh boundary.
    pub const BOUNDARY: Link = Link(MAX_TETS);

    /// A link to neighbour tet `t` (`t < MAX_TETS`).
    #[inline]
    pub const fn tet(t: u32) -> Link {
        debug_assert!(t < MAX_TETS);
        Link(t)
    }

    /// A link to constrained face `c` (`c < MAX_TETS`).
    #[inline]
    pub const fn constrained(c: u32) -> Link {
        debug_assert!(c < MAX_TETS);
        Link(c | Self::CONSTRAINED_BIT)
    }

    /// True when the face is a scene triangle: a ray crossing it hits.
    #[inline]
    pub const fn is_constrained(self) -> bool {
        self.0 & Self::CONSTRAINED_BIT != 0
    }

    /// True when the face is on the mesh boundary.
    #[inline]
    pub const fn is_boundary(self) -> bool {
        self.0 == MAX_TETS
    }

    /// Index of the neighbour tet, if the link names one.
    #[inline]
    pub const fn as_tet(self) -> Option<u32> {
        if self.0 < MAX_TETS {
            Some(self.0)
        } else {
            None
        }
    }

    /// Index into the constrained-face table, if the face is constrained.
    #[inline]
    pub const fn as_constrained(self) -> Option<u32> {
        if self.is_constrained() {
            Some(self.0 & !Self::CONSTRAINED_BIT)
        } else {
            None
        }
    }

    /// Decodes the link.
    #[inline]
    pub const fn kind(self) -> LinkKind {
        if self.is_constrained() {
            LinkKind::Constrained(self.0 & !Self::CONSTRAINED_BIT)
        } else if self.0 == MAX_TETS {
            LinkKind::Boundary
        } else {
            LinkKind::Tet(self.0)
        }
    }
}

impl std::fmt::Debug for Link {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.kind() {
            LinkKind::Tet(t) => write!(f, "Tet({t})"),
            LinkKind::Boundary => write!(f, "Boundary"),
            LinkKind::Constrained(c) => write!(f, "Constrained({c})"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodes_and_decodes_each_kind() {
        assert_eq!(Link::tet(0).kind(), LinkKind::Tet(0));
        assert_eq!(Link::tet(MAX_TETS - 1).kind(), LinkKind::Tet(MAX_TETS - 1));
        assert_eq!(Link::BOUNDARY.kind(), LinkKind::Boundary);
        assert_eq!(Link::constrained(0).kind(), LinkKind::Constrained(0));
        assert_eq!(
            Link::constrained(MAX_TETS - 1).kind(),
            LinkKind::Constrained(MAX_TETS - 1)
        );
        assert!(Link::constrained(5).is_constrained());
        assert!(!Link::BOUNDARY.is_constrained());
        assert!(Link::BOUNDARY.is_boundary());
        assert_eq!(Link::tet(7).as_tet(), Some(7));
        assert_eq!(Link::constrained(7).as_tet(), None);
        assert_eq!(Link::constrained(7).as_constrained(), Some(7));
    }
}
