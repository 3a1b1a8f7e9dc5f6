//! `raypack info SCENE [--json]`: what a scene file holds — primitive counts by
//! kind, bounds, camera, lights, materials — and how long it took to load.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use glam::Vec3;

use crate::cli::args::load_scene;
use crate::cli::error::CliResult;
use crate::geometry::PrimitiveKind;
use crate::scene::{CameraSpec, InstancingSummary, Light, Material, Scene};

/// Options of `info`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (.nff, .obj, .ply, .ply.gz, .toml), or `gen:NAME[:N[:SEED]]` for a generated scene.
    pub scene: PathBuf,
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
    let report = report(&scene, load_seconds);
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
    out
}
