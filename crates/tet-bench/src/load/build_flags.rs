//! How a scene's mesh is built: the build flags (`--quality`,
//! `--min-dihedral`, `--max-steiner`, `--optimize`, `--walls`, `--no-box`,
//! …) that every command building a scene takes, the walls that cut the
//! enclosing box into parts, the cap on Steiner points, and the TetGen
//! options they map to.

use clap::Args;

/// How to build a mesh from a scene.
#[derive(Debug, Clone, Copy, Args)]
pub struct BuildFlags {
    /// TetGen quality bound (radius-edge ratio, `-q`); off by default (`-pY` only).
    #[arg(long)]
    pub quality: Option<f64>,
    /// Refine tets whose smallest dihedral angle is below this many
    /// degrees (slivers; TetGen `-q<ratio>/<degrees>`), with or without
    /// `--quality`.
    #[arg(long, value_name = "DEGREES")]
    pub min_dihedral: Option<f64>,
    /// Cap on the Steiner points of the quality refinement (`-S`; the
    /// points TetGen adds to recover the scene's edges and faces do not
    /// count): a number, or a percentage of the scene's vertices (`1%`).
    /// With `--min-dihedral 2`, 1 % already removes the worst slivers.
    #[arg(long, value_name = "N|P%", value_parser = parse_max_steiner)]
    pub max_steiner: Option<MaxSteiner>,
    /// TetGen's mesh optimisation `LEVEL/SCHEME` (`-O`): up to 2^LEVEL − 1
    /// passes (LEVEL 0 to 9) of flips (SCHEME bit 1), smoothing (2) and
    /// vertex insertion/deletion (4). Default: TetGen's 2/7.
    #[arg(long, value_name = "LEVEL/SCHEME", value_parser = parse_optimization)]
    pub optimize: Option<tet_build::tetgen_options::Optimization>,
    /// Dihedral angle in degrees above which TetGen's optimisation works on
    /// a tet (`-o/`; TetGen's default 165).
    #[arg(long, value_name = "DEGREES")]
    pub max_dihedral: Option<f64>,
    /// Time limit for TetGen in seconds (the build runs in a worker
    /// process). A part of a walled or out-of-core build has at most 10 s
    /// plus 2 ms per point and triangle of its input, ten to thirty times
    /// what such a part takes; one that runs longer is stuck, and has its
    /// walls moved and is built again (in a job: by `build --plan` again,
    /// see `job status`).
    #[arg(long, default_value_t = 600.0)]
    pub time_limit: f64,
    /// Do not add the enclosing box around the scene.
    #[arg(long)]
    pub no_box: bool,
    /// Make the enclosing box hold the camera and lights too (10 % margin),
    /// so that primary rays start in the camera's tet; by default it is
    /// tight around the scene (0.2 % margin) and rays from a camera outside
    /// enter through the mesh boundary.
    #[arg(long, conflicts_with = "no_box")]
    pub wide_box: bool,
    /// Skip Hilbert reordering of points and tets.
    #[arg(long)]
    pub no_sort: bool,
    /// Do not split triangles that cross, touch in their interiors or
    /// overlap: such a scene then fails with the list of intersecting
    /// pairs instead of being resolved.
    #[arg(long)]
    pub no_resolve: bool,
    /// Cut the enclosing box into parts with exact walls between them (the
    /// out-of-core builder's recursive planes), tetrahedralize the parts
    /// in parallel and merge them: the walls break up the long sliver fans
    /// of the unrefined `-pY` mesh, which every ray crosses. `auto`: dense
    /// regions cut until each part's predicted TetGen peak is about 28 MiB
    /// (light parts and empty margins left whole; where no walled build
    /// succeeds, the scene in one piece); `N`: every part cut to the same
    /// depth, N parts (rounded up to a power of two); `none`: one TetGen
    /// run for the whole scene. Default: `auto`, or `none` with
    /// `--no-box`, `--quality` or `--min-dihedral` (the papers' refined
    /// builds are one piece).
    #[arg(long, value_name = "N|auto|none", value_parser = parse_walls)]
    pub walls: Option<Walls>,
}

impl BuildFlags {
    /// The walls these flags build with: `--walls` as given, else `auto`
    /// for the unrefined build in a box and `none` where there is no box
    /// to cut or a quality bound is asked for (the papers' refined builds
    /// are one piece).
    pub fn walls(&self) -> Walls {
        self.walls.unwrap_or(
            if self.no_box || self.quality.is_some() || self.min_dihedral.is_some() {
                Walls::None
            } else {
                Walls::Auto
            },
        )
    }

    /// These flags with the walls they build with spelled out: builds that
    /// come out the same compare equal.
    pub fn resolved(&self) -> BuildFlags {
        BuildFlags {
            walls: Some(self.walls()),
            ..*self
        }
    }

    /// The TetGen options these flags ask for: every TetGen flag given
    /// replaces its default, the rest keep [`tet_build::tetgen_options::TetgenOptions::default`]. The
    /// one mapping for in-core, out-of-core and job builds.
    /// `--max-steiner P%` is resolved against the scene's
    /// `scene_vertices` (rounded up; the out-of-core parts each get the
    /// resulting cap).
    #[cfg_attr(not(feature = "tetgen"), allow(dead_code))]
    pub fn tetgen_options(
        &self,
        scene_vertices: usize,
    ) -> tet_build::tetgen_options::TetgenOptions {
        let d = tet_build::tetgen_options::TetgenOptions::default();
        tet_build::tetgen_options::TetgenOptions {
            quality: self.quality,
            max_steiner: self.max_steiner.map(|m| m.resolve(scene_vertices)),
            min_dihedral: self.min_dihedral.or(d.min_dihedral),
            optimization: self.optimize.or(d.optimization),
            max_dihedral: self.max_dihedral.or(d.max_dihedral),
            ..d
        }
    }
}

/// How finely `--walls` cuts the enclosing box.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Walls {
    /// Parts of about 28 MiB predicted TetGen peak
    /// (`tet_build::outofcore::split::RAY_PART_TARGET_BYTES`, the size every
    /// build shaped for rays cuts toward; if that build fails: one part per about
    /// [`Walls::TRIANGLES_PER_PART`] scene triangles, uniform depth; if
    /// that fails too: the scene in one piece, the switches saying why).
    Auto,
    /// This many parts (rounded up to a power of two).
    Parts(u32),
    /// The scene in one piece: one TetGen run, no walls.
    None,
}

#[cfg_attr(not(feature = "tetgen"), allow(dead_code))]
impl Walls {
    /// `auto`'s fallback: scene triangles per part at uniform depth (Torus
    /// Knots: 32 parts, Armadillo and Nefertiti: 64).
    pub const TRIANGLES_PER_PART: usize = 2_000;

    /// The depth of the cut tree (`2^depth` parts, at most 4096) for a
    /// scene of `triangles` triangles.
    pub fn depth(self, triangles: usize) -> usize {
        let parts = match self {
            Walls::None => 1,
            Walls::Parts(n) => n as usize,
            Walls::Auto => {
                let x = triangles as f64 / Self::TRIANGLES_PER_PART as f64;
                x.max(1.0).log2().round().exp2() as usize
            }
        };
        parts.clamp(1, 4096).next_power_of_two().trailing_zeros() as usize
    }
}

/// `--max-steiner`: a number of Steiner points, or a share of the scene's
/// vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaxSteiner {
    /// At most this many.
    Count(u64),
    /// At most this percentage of the scene's vertices (rounded up).
    Percent(f64),
}

impl MaxSteiner {
    /// The cap for a scene of `vertices` vertices.
    pub fn resolve(self, vertices: usize) -> u64 {
        match self {
            MaxSteiner::Count(n) => n,
            MaxSteiner::Percent(p) => (vertices as f64 * p / 100.0).ceil() as u64,
        }
    }
}

/// Parses `--walls N` (1 to 4096 parts), `--walls auto` or `--walls none`.
fn parse_walls(s: &str) -> Result<Walls, String> {
    if s.trim().eq_ignore_ascii_case("auto") {
        return Ok(Walls::Auto);
    }
    if s.trim().eq_ignore_ascii_case("none") {
        return Ok(Walls::None);
    }
    s.trim()
        .parse::<u32>()
        .ok()
        .filter(|n| (1..=4096).contains(n))
        .map(Walls::Parts)
        .ok_or_else(|| {
            format!("`{s}` is neither a count of parts from 1 to 4096 nor `auto` or `none`")
        })
}

/// Parses `--max-steiner N` or `--max-steiner P%` (P in (0, 1000]).
fn parse_max_steiner(s: &str) -> Result<MaxSteiner, String> {
    match s.strip_suffix('%') {
        Some(p) => p
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|p| *p > 0.0 && *p <= 1000.0)
            .map(MaxSteiner::Percent)
            .ok_or_else(|| format!("`{s}` is not a percentage above 0 and at most 1000")),
        None => s
            .parse::<u64>()
            .map(MaxSteiner::Count)
            .map_err(|_| format!("`{s}` is neither a count of points nor a percentage (`1%`)")),
    }
}

/// Parses `--optimize LEVEL/SCHEME` (`7/7`; a bare `LEVEL` keeps scheme 7).
fn parse_optimization(s: &str) -> Result<tet_build::tetgen_options::Optimization, String> {
    let (level, scheme) = s.split_once('/').unwrap_or((s, "7"));
    let digit = |x: &str, max: u8, what: &str| {
        x.parse::<u8>()
            .ok()
            .filter(|v| *v <= max)
            .ok_or_else(|| format!("{what} `{x}` is not a number from 0 to {max}"))
    };
    Ok(tet_build::tetgen_options::Optimization {
        level: digit(level, 9, "level")?,
        scheme: digit(scheme, 7, "scheme")?,
    })
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;
    use crate::cli::{Cli, Command};

    /// `--walls`: counts and `auto`, the tree depth they give, and what
    /// is refused.
    #[test]
    fn walls_parse_as_part_counts_or_auto() {
        assert_eq!(parse_walls("auto"), Ok(Walls::Auto));
        assert_eq!(parse_walls(" 8 "), Ok(Walls::Parts(8)));
        assert_eq!(parse_walls("None"), Ok(Walls::None));
        assert_eq!(Walls::None.depth(100_000), 0);
        for bad in ["0", "4097", "-2", "x", ""] {
            assert!(parse_walls(bad).is_err(), "{bad}");
        }
        // Rounded up to a power of two.
        assert_eq!(Walls::Parts(1).depth(10), 0);
        assert_eq!(Walls::Parts(5).depth(10), 3);
        assert_eq!(Walls::Parts(4096).depth(10), 12);
        // One part per about 2,000 triangles, to the nearest power of two.
        assert_eq!(Walls::Auto.depth(500), 0);
        assert_eq!(Walls::Auto.depth(77_760), 5);
        assert_eq!(Walls::Auto.depth(100_000), 6);
        assert_eq!(Walls::Auto.depth(u32::MAX as usize), 12);
    }

    #[test]
    fn steiner_caps_parse_as_counts_or_shares_of_the_vertices() {
        assert_eq!(parse_max_steiner("500"), Ok(MaxSteiner::Count(500)));
        assert_eq!(parse_max_steiner("1%"), Ok(MaxSteiner::Percent(1.0)));
        assert_eq!(parse_max_steiner("0.5 %"), Ok(MaxSteiner::Percent(0.5)));
        for bad in [
            "", "%", "-1", "0%", "-2%", "1e9999%", "nan%", "x", "5 points",
        ] {
            assert!(parse_max_steiner(bad).is_err(), "{bad}");
        }
        // 1 % of 38,888 vertices is 388.88: rounded up.
        assert_eq!(MaxSteiner::Percent(1.0).resolve(38_888), 389);
        assert_eq!(MaxSteiner::Percent(1.0).resolve(0), 0);
        assert_eq!(MaxSteiner::Count(7).resolve(1_000_000), 7);
    }

    /// The walls a build uses: `auto` by default, none where there is no
    /// box or a quality bound is asked for, and what `--walls` says.
    #[test]
    fn builds_are_walled_by_default_but_not_refined_or_boxless_ones() {
        let walls = |extra: &[&str]| {
            let mut argv = vec!["tet-bench", "build", "torus-knot", "-o", "x.tmesh"];
            argv.extend_from_slice(extra);
            let Command::Build(a) = Cli::try_parse_from(argv).unwrap().command else {
                panic!("not build")
            };
            (a.build.walls(), a.build.resolved().walls)
        };
        assert_eq!(walls(&[]), (Walls::Auto, Some(Walls::Auto)));
        assert_eq!(walls(&["--no-box"]).0, Walls::None);
        assert_eq!(walls(&["--quality", "5"]).0, Walls::None);
        assert_eq!(walls(&["--min-dihedral", "2"]).0, Walls::None);
        assert_eq!(walls(&["--max-steiner", "1%"]).0, Walls::Auto);
        assert_eq!(walls(&["--walls", "none"]).0, Walls::None);
        assert_eq!(
            walls(&["--walls", "8", "--quality", "5"]).0,
            Walls::Parts(8)
        );
    }
}
