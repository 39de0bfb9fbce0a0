//! TetGen's switches as data ([`TetgenOptions`], [`Optimization`]): what a
//! build asks of TetGen, available without the `tetgen` feature (and its
//! AGPL code) so that command lines, job files and reports can name them;
//! running TetGen is the business of the `tetgen` module.

/// TetGen switches we expose (the switch string is always ours, never the caller's).
#[derive(Clone, Debug, PartialEq)]
pub struct TetgenOptions {
    /// `-q<ratio>`: refine until every tet's radius-edge ratio is at most
    /// `ratio` (TetGen's default 2.0 when `Some(2.0)`). Multiplies tets 5–9×.
    pub quality: Option<f64>,
    /// `-q<ratio>/<degrees>`: also refine tets whose smallest dihedral
    /// angle is below `degrees` (slivers). Without [`Self::quality`] the
    /// ratio bound is [`NO_RATIO`] (no radius-edge refinement).
    pub min_dihedral: Option<f64>,
    /// `-S<n>`: at most `n` Steiner points from the quality refinement
    /// (`-q`), which otherwise may not terminate between near-parallel
    /// facets. Unlike TetGen's own driver, ours does not count the points
    /// the boundary recovery added (thousands on some scenes, which left a
    /// smaller cap no refinement at all).
    pub max_steiner: Option<u64>,
    /// `-T<tol>`: coplanarity tolerance (TetGen's default 1e-8).
    pub coplanar_tolerance: Option<f64>,
    /// `-Y`: keep the input surface mesh (no Steiner points on facets). On by default.
    pub preserve_surface: bool,
    /// `-Y/2` (with [`Self::preserve_surface`]): where recovering a
    /// boundary segment needs a Steiner point, TetGen puts it in the
    /// volume, halfway between the segment and the one crossing it, and
    /// recovers the segment again, instead of splitting the segment and
    /// moving the point off it later (its default). Off by default; the
    /// out-of-core builder's first relaxation for a part `-Y` fails on.
    pub steiner_off_surface: bool,
    /// `-c`: keep the convex hull (otherwise TetGen removes tets outside the
    /// closed boundary it can find, which empties open scenes).
    pub keep_convex_hull: bool,
    /// `-n`: also output tet neighbours.
    pub neighbors: bool,
    /// `-nn`: also output, for every output face, the tets on its two sides
    /// (`TetgenOutput::face_tets` of the `tetgen` module); implies [`TetgenOptions::neighbors`].
    pub face_tets: bool,
    /// `-O<level>/<scheme>`: TetGen's mesh optimisation after the build
    /// (flips, smoothing and vertex insertion/deletion by scheme bits 1, 2
    /// and 4; up to `2^level − 1` passes). `None` keeps TetGen's default
    /// (level 2, scheme 7), which runs on every `-p` build.
    pub optimization: Option<Optimization>,
    /// `-o/<degrees>`: the dihedral angle above which the optimisation
    /// works on a tet (TetGen's default 165°). Smaller values remove more
    /// slivers and cost more time.
    pub max_dihedral: Option<f64>,
}

/// The radius-edge bound written with [`TetgenOptions::min_dihedral`]
/// alone: large enough that no tet is refined for its ratio.
pub const NO_RATIO: f64 = 1000.0;

/// TetGen's mesh optimisation setting (`-O<level>/<scheme>`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Optimization {
    /// 0 (off) to 9: up to `2^level − 1` optimisation passes.
    pub level: u8,
    /// Bit set: 1 edge/face flips, 2 vertex smoothing, 4 vertex insertion
    /// and deletion (0 to 7).
    pub scheme: u8,
}

impl Default for TetgenOptions {
    fn default() -> Self {
        TetgenOptions {
            quality: None,
            min_dihedral: None,
            max_steiner: None,
            coplanar_tolerance: None,
            preserve_surface: true,
            steiner_off_surface: false,
            keep_convex_hull: true,
            neighbors: false,
            face_tets: false,
            optimization: None,
            max_dihedral: None,
        }
    }
}

impl TetgenOptions {
    /// The TetGen switch string, e.g. `pYczQ`.
    pub fn switches(&self) -> String {
        let mut s = String::from("p");
        if self.preserve_surface {
            s.push('Y');
            if self.steiner_off_surface {
                s.push_str("/2");
            }
        }
        if self.keep_convex_hull {
            s.push('c');
        }
        if self.face_tets {
            s.push_str("nn");
        } else if self.neighbors {
            s.push('n');
        }
        match (self.quality, self.min_dihedral) {
            (Some(q), None) => s.push_str(&format!("q{q}")),
            (q, Some(a)) => s.push_str(&format!("q{}/{a}", q.unwrap_or(NO_RATIO))),
            (None, None) => {}
        }
        if let Some(n) = self.max_steiner {
            s.push_str(&format!("S{n}"));
        }
        if let Some(o) = self.optimization {
            s.push_str(&format!("O{}/{}", o.level, o.scheme));
        }
        if let Some(a) = self.max_dihedral {
            s.push_str(&format!("o/{a}"));
        }
        if let Some(t) = self.coplanar_tolerance {
            s.push_str(&format!("T{t:e}"));
        }
        s.push_str("zQ");
        s
    }
}
