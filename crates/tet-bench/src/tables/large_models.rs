//! Large models (Lauterbach et al. 2007, §6: Ray-Strips pay off when a
//! BVH no longer fits in memory): the same Torus Knots view with every
//! knot tessellated more finely (`dense-knots:N`,
//! [`tet_build::procedural::dense_torus_knots`]) at 1 M, 10 M and 30 M
//! triangles, and per size the bytes, build time and primary-ray speed of
//! Ray-Strips, the obvhs BVH and — where TetGen's predicted peak fits in
//! half the free memory — the Tet20 walk over the scene's CDT.
//!
//! Ray-Strips and the BVH are built over the scene's triangles directly (a
//! surface mesh: points and constrained faces, and one placeholder tet for
//! the renderer's camera location), so their
//! rows need no tetrahedralization; Tet20's build time is the whole
//! pipeline's (clean, resolve, TetGen, assemble, reorder).

use anyhow::{Result, bail};
use glam::{DVec3, Vec3};
use std::fmt::Write as _;
use tet_build::procedural::dense_torus_knots;
use tet_build::scene::Scene;
use tet_core::link::Link;
use tet_core::mesh::{ConstrainedFace, FaceSide};
use tet_core::predicates::orient3d_f32;
use tet_core::{Attributes, TetMesh};
use tet_trace_cpu::render::RenderOptions;

use super::doc::{LargeModelRow, LargeStructure, TablesDoc};
use crate::load::Loaded;
use crate::methods::bvh::BvhTracer;
use crate::methods::layouts::strips_bytes;
use crate::methods::method::Method;
use crate::timing::{Frames, time_method};

/// Bytes each structure needs per triangle while it is built and timed
/// (the structure, its build's scratch and the renderer's second counting
/// BVH), with room to spare: a size whose estimate exceeds the free memory
/// is skipped with a note instead of swapping or being killed.
const PEAK_BYTES_PER_TRIANGLE: u64 = 400;

/// Free memory (`MemAvailable` of `/proc/meminfo`), bytes; `None` where
/// the system does not say.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The scene's triangles as the mesh Ray-Strips and the BVH are built
/// from (they read only points and constrained faces), plus one
/// placeholder tet enclosing the scene and the camera: the renderer
/// locates the camera in the mesh before tracing, and these tracers
/// ignore the start it finds.
fn surface_mesh(scene: &Scene, camera: Vec3) -> TetMesh {
    let (lo, hi) = scene
        .vertices
        .iter()
        .fold((camera, camera), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let centre = 0.5 * (lo.as_dvec3() + hi.as_dvec3());
    // A regular tet's inscribed sphere has a third of its circumradius:
    // corners at 3·radius (doubled for room) hold the whole box.
    let radius = 0.5 * (hi - lo).as_dvec3().length() + 1.0;
    let corner = |x: f64, y: f64, z: f64| {
        (centre + 6.0 * radius * DVec3::new(x, y, z) / 3f64.sqrt()).as_vec3()
    };
    let mut placeholder = [
        corner(1.0, 1.0, 1.0),
        corner(1.0, -1.0, -1.0),
        corner(-1.0, 1.0, -1.0),
        corner(-1.0, -1.0, 1.0),
    ];
    if orient3d_f32(
        placeholder[0],
        placeholder[1],
        placeholder[2],
        placeholder[3],
    ) < 0.0
    {
        placeholder.swap(0, 1);
    }
    let n = scene.vertices.len() as u32;
    let mut points = scene.vertices.clone();
    points.extend(placeholder);
    TetMesh {
        points,
        tets: vec![[n, n + 1, n + 2, n + 3]],
        neighbors: vec![[Link::BOUNDARY; 4]],
        constrained: scene
            .triangles
            .iter()
            .enumerate()
            .map(|(i, &vertices)| ConstrainedFace {
                triangle: i as u32,
                vertices,
                front: FaceSide::NONE,
                back: FaceSide::NONE,
            })
            .collect(),
        triangle_count: scene.triangles.len() as u32,
        attributes: Attributes::default(),
    }
}

/// One structure's row: built once to count its bytes, then rendered by
/// [`time_method`], whose set-up time (the second build) is the build
/// time.
fn structure(
    loaded: &Loaded,
    method: Method,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Result<LargeStructure> {
    let triangles = loaded.mesh.constrained.len().max(1) as f64;
    let bytes = match method {
        Method::Strips => strips_bytes(&loaded.mesh)?.total_bytes,
        Method::Obvhs => {
            let (hierarchy, geometry) = BvhTracer::new(&loaded.mesh).bytes();
            hierarchy + geometry
        }
        _ => bail!("not a structure over triangles: {}", method.name()),
    };
    eprintln!("  {}: rendering with {}", loaded.name, method.name());
    let render = time_method(loaded, method, opts, frames, pool)?.0;
    // The render's set-up is the structure's build.
    let build_s = render.setup_s;
    Ok(LargeStructure {
        structure: method.name().to_string(),
        bytes,
        bytes_per_triangle: bytes as f64 / triangles,
        build_s,
        render,
        memory: None,
    })
}

/// Without TetGen there is no CDT to build.
#[cfg(not(feature = "tetgen"))]
fn tet20(
    _: Scene,
    _: &str,
    _: Option<u64>,
    _: &RenderOptions,
    _: Frames,
    _: &rayon::ThreadPool,
) -> Result<std::result::Result<LargeStructure, String>> {
    Ok(Err(
        "tet20 not built: this binary was built without TetGen".into()
    ))
}

#[cfg(feature = "tetgen")]
/// Tet20 over the scene's CDT: built in core where TetGen's predicted peak
/// fits in half the free memory, else (or with `limit`) out of core under
/// `limit` or half the free memory, by `tet-bench build SPEC
/// --memory-limit L` in a process of its own, as a user runs it; or why
/// not.
fn tet20(
    scene: Scene,
    spec: &str,
    limit: Option<u64>,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Result<std::result::Result<LargeStructure, String>> {
    use super::doc::TABLE_FLAGS;
    use crate::load::{from_scene, with_mesh};
    use crate::methods::layouts::layout_bytes;
    use crate::tables::out_of_core::build_in_own_process;

    let predicted = tet_build::outofcore::memory_model::predict_peak_memory(
        scene.vertices.len(),
        scene.triangles.len(),
    );
    let limit = limit.or_else(|| {
        available_memory()
            .filter(|&free| predicted > free / 2)
            .map(|free| free / 2)
    });
    let (loaded, build_s, memory): (Loaded, f64, _) = match limit {
        None => {
            eprintln!("  {}: building the CDT", scene.name);
            let loaded = from_scene(scene, &TABLE_FLAGS, true)?;
            let build_s = loaded.build.as_ref().map_or(0.0, |b| b.total_s);
            (loaded, build_s, None)
        }
        Some(limit) => {
            eprintln!(
                "  {spec}: building the CDT out of core under {:.1} MiB",
                limit as f64 / (1024.0 * 1024.0)
            );
            let file = std::env::temp_dir().join(format!(
                "tet-bench-large-model-{}.tmesh",
                std::process::id()
            ));
            let start = std::time::Instant::now();
            let built = build_in_own_process(spec, limit, pool.current_num_threads(), &file);
            let build_s = start.elapsed().as_secs_f64();
            let _ = std::fs::remove_file(&file);
            match built {
                Ok((mesh, memory)) => (with_mesh(scene, mesh, None), build_s, Some(memory)),
                Err(e) => {
                    return Ok(Err(format!(
                        "tet20 not built: out of core under {:.1} MiB: {e:#}",
                        limit as f64 / (1024.0 * 1024.0)
                    )));
                }
            }
        }
    };
    let bytes = layout_bytes(&loaded.mesh)
        .1
        .iter()
        .find(|l| l.name == Method::Tet20.name())
        .map_or(0, |l| l.total_bytes);
    let triangles = loaded.mesh.constrained.len().max(1) as f64;
    eprintln!("  {}: rendering with tet20", loaded.name);
    let render = time_method(&loaded, Method::Tet20, opts, frames, pool)?.0;
    Ok(Ok(LargeStructure {
        structure: Method::Tet20.name().to_string(),
        bytes,
        bytes_per_triangle: bytes as f64 / triangles,
        build_s,
        render,
        memory,
    }))
}

/// Measures one size.
fn measure_one(
    triangles: u64,
    limit: Option<u64>,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Result<LargeModelRow> {
    if let Some(free) = available_memory() {
        let need = triangles.saturating_mul(PEAK_BYTES_PER_TRIANGLE);
        if need > free {
            bail!(
                "skipped: about {:.1} GB needed, {:.1} GB free",
                need as f64 / 1e9,
                free as f64 / 1e9
            );
        }
    }
    let scene = dense_torus_knots(triangles);
    let spec = format!("dense-knots:{triangles}");
    eprintln!("scene {spec} ({} triangles)", scene.triangles.len());
    let camera = scene
        .camera
        .expect("the dense knots carry the Torus Knots camera");
    let loaded = Loaded {
        name: spec.clone(),
        mesh: surface_mesh(&scene, camera.position),
        scene: None,
        camera,
        lights: scene.lights.clone(),
        build: None,
    };
    let mut structures = vec![
        structure(&loaded, Method::Strips, opts, frames, pool)?,
        structure(&loaded, Method::Obvhs, opts, frames, pool)?,
    ];
    drop(loaded);
    let scene_triangles = scene.triangles.len();
    let note = match tet20(scene, &spec, limit, opts, frames, pool)? {
        Ok(row) => {
            structures.push(row);
            None
        }
        Err(why) => Some(why),
    };
    Ok(LargeModelRow {
        scene: spec,
        triangles: scene_triangles,
        structures,
        note,
        error: None,
    })
}

/// Measures every size (an error on one size becomes that row's `error`).
pub fn measure_all(
    sizes: &[u64],
    limit: Option<u64>,
    opts: &RenderOptions,
    frames: Frames,
    pool: &rayon::ThreadPool,
) -> Vec<LargeModelRow> {
    sizes
        .iter()
        .map(|&n| {
            measure_one(n, limit, opts, frames, pool).unwrap_or_else(|e| {
                eprintln!("  dense-knots:{n}: {e:#}");
                LargeModelRow {
                    scene: format!("dense-knots:{n}"),
                    triangles: 0,
                    structures: Vec::new(),
                    note: None,
                    error: Some(format!("{e:#}")),
                }
            })
        })
        .collect()
}

/// The table.
pub fn markdown(m: &mut String, doc: &TablesDoc) {
    if doc.large_models.is_empty() {
        if let Some(note) = &doc.large_models_note {
            let _ = writeln!(
                m,
                "\n## Large models (Lauterbach et al. 2007, §6)\n\n{note}"
            );
        }
        return;
    }
    let _ = writeln!(m, "\n## Large models (Lauterbach et al. 2007, §6)\n");
    let _ = writeln!(
        m,
        "Torus Knots with every knot tessellated more finely (`dense-knots:N`), same camera; Ray-Strips (default options) and obvhs over the triangles, Tet20 over the CDT: in core where TetGen's predicted peak fits in half the free memory, else (or with `--large-models-limit`) out of core under half the free memory (`build --memory-limit` in a process of its own; \"built\" gives the limit, the parts and the process tree's peak). Bytes include the vertices; build s for Tet20 is the whole pipeline (out of core: the build process, writing and reading back the mesh file included). {}×{}, {} threads, best of {} frames. The paper's large models (Buddha 1.1 M, Thai 10 M, Lucy 28 M triangles) showed Ray-Strips fitting where the BVH did not.\n",
        doc.setup.width, doc.setup.height, doc.setup.threads, doc.setup.frames
    );
    let _ = writeln!(
        m,
        "| scene | triangles | structure | built | MB | B/triangle | build s | tets/ray | Mrays/s | ratio to obvhs |"
    );
    let _ = writeln!(m, "|---|---:|---|---|---:|---:|---:|---:|---:|---:|");
    for row in &doc.large_models {
        if let Some(e) = &row.error {
            let _ = writeln!(m, "| {} | – | – | – | – | – | – | – | – | {e} |", row.scene);
            continue;
        }
        let bvh = row
            .structures
            .iter()
            .find(|s| s.structure == Method::Obvhs.name())
            .map(|s| s.render.mrays_per_s);
        for s in &row.structures {
            let ratio = bvh
                .filter(|&b| b > 0.0)
                .map_or("–".into(), |b| format!("{:.2}", s.render.mrays_per_s / b));
            let built = match &s.memory {
                None if s.structure == Method::Tet20.name() => "in core".to_string(),
                None => "–".to_string(),
                Some(r) => format!(
                    "out of core under {:.0} MiB: {} parts, tree peak {}",
                    r.limit_bytes as f64 / (1024.0 * 1024.0),
                    r.parts,
                    r.tree_peak_kib
                        .map_or("–".into(), |k| format!("{:.0} MiB", k as f64 / 1024.0))
                ),
            };
            let tets = if s.structure == Method::Tet20.name() {
                format!("{:.1}", s.render.tets_per_ray)
            } else {
                "–".to_string()
            };
            let _ = writeln!(
                m,
                "| {} | {} | {} | {built} | {:.1} | {:.1} | {:.2} | {tets} | {:.2} | {ratio} |",
                row.scene,
                row.triangles,
                s.structure,
                s.bytes as f64 / 1e6,
                s.bytes_per_triangle,
                s.build_s,
                s.render.mrays_per_s,
            );
        }
        if let Some(note) = &row.note {
            let _ = writeln!(
                m,
                "| {} | {} | – | – | – | – | – | – | – | {note} |",
                row.scene, row.triangles
            );
        }
    }
}
