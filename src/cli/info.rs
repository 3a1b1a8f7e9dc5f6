//! `raypack info SCENE [--bvh] [--json]`: what a scene file holds — primitive
//! counts by kind, bounds, camera, lights, materials — and how long it took to
//! load; with `--bvh`, the BVH raypack builds for it (each level of an
//! instanced scene's): its shape, memory, and the walks its size chooses.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use glam::Vec3;

use crate::accel::Bvh;
use crate::accel::bvh::BvhInfo;
use crate::accel::two_level::TwoLevel;
use crate::cli::args::load_scene;
use crate::cli::error::CliResult;
use crate::geometry::PrimitiveKind;
use crate::scene::{CameraSpec, InstancingSummary, Light, Material, Scene};

/// Options of `info`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (.nff, .obj, .ply, .ply.gz, .toml), or `gen:NAME[:N[:SEED]]` for a generated scene.
    pub scene: PathBuf,
    /// Also build raypack's BVH for the scene, as `render` and `bench` build
    /// it, and describe it: nodes, leaves, depth, SAH cost, memory, and how
    /// incoherent and scattered packets walk a tree of its size.
    #[arg(long)]
    pub bvh: bool,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Lights and materials listed in the text report before "… and N more".
const LISTED: usize = 16;

/// The report, as printed with `--json`.
#[derive(serde::Serialize)]
struct Report<'a> {
    source: &'a str,
    load_seconds: f64,
    /// Primitives rays meet, instanced ones counted once per instance.
    primitives: u64,
    /// Instances, meshes, unique and instanced counts, and bytes per level.
    #[serde(skip_serializing_if = "Option::is_none")]
    instancing: Option<InstancingSummary>,
    /// What the reader left out or changed.
    #[serde(skip_serializing_if = "<[String]>::is_empty")]
    notes: &'a [String],
    counts: BTreeMap<PrimitiveKind, usize>,
    /// Triangles with per-vertex shading normals.
    smooth_triangles: usize,
    /// Bounds of the bounded primitives (None when there are none).
    bounds: Option<Bounds>,
    camera: Option<CameraSpec>,
    background: Vec3,
    lights: &'a [Light],
    materials: &'a [Material],
    /// raypack's BVH for the scene (`--bvh`).
    #[serde(skip_serializing_if = "Option::is_none")]
    bvh: Option<Structure>,
}

/// raypack's structure for a scene: one BVH, or the levels of a two-level one.
#[derive(serde::Serialize)]
struct Structure {
    /// Time to build it all.
    build_seconds: f64,
    /// The last-level cache the walks are chosen against ([`Bvh::cache_bytes`]).
    cache_bytes: usize,
    /// `scene` (a flat scene's one tree), or `own` (an instanced scene's own
    /// primitives), `top` (the tree over its instances) and `mesh N`.
    levels: Vec<Level>,
}

/// One BVH of a [`Structure`].
#[derive(serde::Serialize)]
struct Level {
    /// `scene`, `own`, `top` or `mesh N` (see [`Structure::levels`]).
    name: String,
    #[serde(flatten)]
    info: BvhInfo,
    /// What single rays read: the 16-wide nodes and the leaves ([`Bvh::walked_bytes`]).
    walked_bytes: usize,
    /// How the lanes of incoherent packets set out: `shared` (the hybrid walk),
    /// or `apart` where the tree outgrows the cache ([`Bvh::outgrows_cache`]).
    incoherent_packets: &'static str,
    /// How the lanes of scattered packets walk: `one after another`, or
    /// `interleaved` in a large tree ([`Bvh::interleaves_scattered`]).
    scattered_packets: &'static str,
}

impl Level {
    fn of(name: String, bvh: &Bvh) -> Self {
        Self {
            name,
            info: bvh.info(),
            walked_bytes: bvh.walked_bytes(),
            incoherent_packets: if bvh.outgrows_cache() { "apart" } else { "shared" },
            scattered_packets: if bvh.interleaves_scattered() {
                "interleaved"
            } else {
                "one after another"
            },
        }
    }
}

/// Build raypack's BVH for `scene` as the engines do (a two-level one for an
/// instanced scene) and describe it.
fn structure(scene: &Scene) -> Structure {
    let start = Instant::now();
    if scene.instances.is_empty() {
        let bvh = Bvh::new(&scene.primitives);
        return Structure {
            build_seconds: start.elapsed().as_secs_f64(),
            cache_bytes: bvh.cache_bytes(),
            levels: vec![Level::of("scene".into(), &bvh)],
        };
    }
    let two_level = TwoLevel::new(scene, Bvh::new);
    let build_seconds = start.elapsed().as_secs_f64();
    let meshes = two_level.meshes().iter().enumerate();
    let levels = [("own", two_level.own()), ("top", two_level.top())]
        .into_iter()
        .map(|(name, bvh)| Level::of(name.into(), bvh))
        .chain(meshes.map(|(i, mesh)| Level::of(format!("mesh {i}"), mesh)))
        .collect();
    Structure {
        build_seconds,
        cache_bytes: two_level.top().cache_bytes(),
        levels,
    }
}

/// An axis-aligned box as `{ "min": [x, y, z], "max": [x, y, z] }`.
#[derive(Clone, Copy, serde::Serialize)]
struct Bounds {
    min: Vec3,
    max: Vec3,
}

/// Load the scene and print the report; a scene that does not load is bad input (exit 2).
pub fn run(args: Args) -> CliResult {
    let start = Instant::now();
    let (scene, _) = load_scene(&args.scene)?;
    let load_seconds = start.elapsed().as_secs_f64();
    let mut report = report(&scene, load_seconds);
    report.bvh = args.bvh.then(|| structure(&scene));
    let out = if args.json {
        serde_json::to_string_pretty(&report).map_err(anyhow::Error::from)? + "\n"
    } else {
        text(&report)
    };
    crate::cli::stdout::write_str(&out)
}

fn report(scene: &Scene, load_seconds: f64) -> Report<'_> {
    let bounds = scene.bounds();
    Report {
        source: &scene.source,
        load_seconds,
        primitives: scene.id_count(),
        instancing: scene.instancing_summary(),
        notes: &scene.notes,
        counts: scene.counts().into_iter().collect(),
        smooth_triangles: scene.vertex_normals.len(),
        bounds: (!bounds.is_empty()).then_some(Bounds {
            min: bounds.min,
            max: bounds.max,
        }),
        camera: scene.camera,
        background: scene.background,
        lights: &scene.lights,
        materials: &scene.materials,
        bvh: None,
    }
}

/// Bytes as `12.3 MB`.
fn megabytes(bytes: u64) -> String {
    format!("{:.1} MB", bytes as f64 / 1e6)
}

fn vec(v: Vec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

/// "… and N more" after the first [`LISTED`] lines.
fn listed<T>(items: &[T], line: impl Fn(usize, &T) -> String) -> String {
    let mut out: String = items
        .iter()
        .enumerate()
        .take(LISTED)
        .map(|(i, x)| line(i, x) + "\n")
        .collect();
    if items.len() > LISTED {
        out += &format!("  … and {} more\n", items.len() - LISTED);
    }
    out
}

fn text(r: &Report) -> String {
    let mut out = format!("scene       {}\n", r.source);
    out += &format!("loaded in   {:.3} ms\n", 1e3 * r.load_seconds);
    out += &format!("primitives  {}\n", r.primitives);
    for (kind, n) in &r.counts {
        out += &format!("  {:<12} {n}\n", format!("{kind:?}").to_lowercase());
    }
    if let Some(i) = &r.instancing {
        out += &format!(
            "instances   {}
",
            i.line()
        );
        out += &format!(
            "  memory     top: {} own primitives + {} instance records; bottom: {} meshes
",
            megabytes(i.own_bytes),
            megabytes(i.instance_bytes),
            megabytes(i.mesh_bytes)
        );
    }
    for note in r.notes {
        out += &format!("note        {note}\n");
    }
    if r.smooth_triangles > 0 {
        out += &format!("  ({} triangles with vertex normals)\n", r.smooth_triangles);
    }
    let planes = r.counts.get(&PrimitiveKind::Plane).copied().unwrap_or(0);
    let unbounded = if planes > 0 {
        " (planes are unbounded and left out)".to_string()
    } else {
        String::new()
    };
    out += &match r.bounds {
        Some(b) => format!("bounds      {} .. {}{unbounded}\n", vec(b.min), vec(b.max)),
        None => format!("bounds      none{unbounded}\n"),
    };
    out += &match r.camera {
        Some(c) => format!(
            "camera      eye {} center {} up {}\n            fovx {}° fovy {}° {}×{}\n",
            vec(c.eye),
            vec(c.center),
            vec(c.up),
            c.fovx,
            c.fovy,
            c.width,
            c.height
        ),
        None => "camera      none in the file\n".into(),
    };
    out += &format!("background  {}\n", vec(r.background));
    out += &format!("lights      {}\n", r.lights.len());
    out += &listed(r.lights, |_, l| {
        format!("  at {} color {}", vec(l.position), vec(l.color))
    });
    out += &format!("materials   {}\n", r.materials.len());
    out += &listed(r.materials, |i, m| {
        format!(
            "  {i}: color {} kd {} ks {} shine {} T {} ior {}",
            vec(m.color),
            m.kd,
            m.ks,
            m.shine,
            m.transmittance,
            m.ior
        )
    });
    if let Some(s) = &r.bvh {
        out += &structure_text(s);
    }
    out
}

/// The `--bvh` lines: the build, then a line per level (past [`LISTED`]
/// levels, "… and N more").
fn structure_text(s: &Structure) -> String {
    let mut out = format!(
        "bvh         built in {:.3} ms; last-level cache {:.1} MiB\n",
        1e3 * s.build_seconds,
        s.cache_bytes as f64 / f64::from(1 << 20)
    );
    out += &listed(&s.levels, |_, level| {
        let i = &level.info;
        format!(
            "  {:<9} {} primitives, {} leaves (≤ {} each), {} nodes, depth {}, SAH {:.1}; {}, {} walked by single rays; incoherent packets: {}, scattered packets: {}",
            level.name,
            i.primitives,
            i.leaves,
            i.max_leaf_size,
            i.nodes,
            i.max_depth,
            i.sah_cost,
            megabytes(i.bytes as u64),
            megabytes(level.walked_bytes as u64),
            level.incoherent_packets,
            level.scattered_packets
        )
    });
    out
}
