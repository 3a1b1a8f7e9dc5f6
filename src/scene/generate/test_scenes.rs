//! Seeded scenes built in code, for comparing engines before (and besides) the
//! scene files: random triangles, spheres, polygons, transformed objects and
//! planes (the generators of [`random`]), a closed triangle mesh (shared edges
//! everywhere), and a mix of all of them. Each comes with a camera that frames
//! it. The sphereflake is `raypack gen`'s, the SPD's ([`Kind::Sphereflake`]).

use clap::ValueEnum;
use glam::Vec3;

use crate::geometry::{Primitive, Triangle};
use crate::scene::generate::random;
use crate::scene::generate::{Kind, Params};
use crate::scene::{CameraSpec, Material, Scene};

/// The generated scenes, by name.
pub const NAMES: [&str; 7] = [
    "triangles",
    "spheres",
    "polygons",
    "transformed",
    "planes",
    "mesh",
    "mixed",
];

/// The scene called `name` (one of [`NAMES`]) with about `n` primitives, from `seed`.
pub fn by_name(name: &str, n: usize, seed: u64) -> Option<Scene> {
    let prims = match name {
        "triangles" => random::random_triangles(n, seed),
        "spheres" => random::random_spheres(n, seed),
        "polygons" => random::random_polygons(n, seed),
        "transformed" => random::random_transformed(n, seed),
        "planes" => {
            let mut p = random::random_spheres(n.saturating_sub(3), seed);
            p.extend(random::bounding_planes());
            p
        }
        "mesh" => uv_sphere_mesh(Vec3::ZERO, 4.0, n),
        "mixed" => {
            let k = n / 5;
            let mut p = random::random_triangles(k, seed);
            p.extend(random::random_spheres(k, seed + 1));
            p.extend(random::random_polygons(k, seed + 2));
            p.extend(random::random_transformed(k, seed + 3));
            p.extend(uv_sphere_mesh(Vec3::new(0.0, 0.0, -0.4), 0.4, n - 4 * k));
            p.extend(random::bounding_planes());
            p
        }
        _ => return None,
    };
    Some(scene_of(format!("generated:{name}:{n}:{seed}"), prims))
}

/// The scene `spec` names, as `bench` takes it: generated (`gen:…`, see
/// [`from_spec`]) or a file ([`load`](crate::scene::load)); any error as
/// text, which names the spec or the file.
pub fn load_spec(spec: &str) -> Result<Scene, String> {
    match from_spec(spec) {
        Some(generated) => generated,
        None => crate::scene::load(std::path::Path::new(spec)).map_err(|e| e.to_string()),
    }
}

/// The scene named by a command-line argument `gen:NAME[:N[:SEED]]`; None when
/// `spec` does not start with `gen:`. NAME is one of [`NAMES`] (N primitives,
/// 1000 by default; seed 1 by default), or else a kind of `raypack gen`, as
/// [`Kind`] names it (N its `--size`, SEED its `--seed`, each the kind's default
/// when left out), the scene that command writes ([`Params::scene`]):
/// `gen:sphereflake:3` is `raypack gen sphereflake --size 3`, `gen:forest:N`
/// a forest of N instances.
pub fn from_spec(spec: &str) -> Option<Result<Scene, String>> {
    let rest = spec.strip_prefix("gen:")?;
    let mut parts = rest.split(':');
    let name = parts.next().unwrap_or_default();
    let listed = NAMES.contains(&name);
    let number = |part: Option<&str>, what: &str| match part {
        None => Ok(None),
        Some(p) => p
            .parse::<u64>()
            .map(Some)
            .map_err(|_| format!("{spec}: {what} must be a whole number, got `{p}`")),
    };
    Some((|| {
        let n = number(
            parts.next(),
            if listed { "the primitive count" } else { "the size" },
        )?;
        let seed = number(parts.next(), "the seed")?;
        if parts.next().is_some() {
            return Err(format!("{spec}: expected gen:NAME[:N[:SEED]]"));
        }
        if listed {
            return Ok(by_name(name, n.unwrap_or(1000) as usize, seed.unwrap_or(1)).expect("a listed name"));
        }
        let kind = Kind::from_str(name, true).map_err(|_| {
            let kinds: Vec<_> = Kind::ALL.iter().map(|k| k.name()).collect();
            format!(
                "{spec}: unknown generated scene `{name}` (one of {}, or of `raypack gen`: {})",
                NAMES.join(", "),
                kinds.join(", ")
            )
        })?;
        generated(spec, kind, n, seed)
    })())
}

/// The scene `raypack gen` writes for `kind`, `size` and `seed`
/// ([`Params::scene`]), named by `spec`.
fn generated(spec: &str, kind: Kind, size: Option<u64>, seed: Option<u64>) -> Result<Scene, String> {
    let size = size
        .map(|n| u32::try_from(n).map_err(|_| format!("{spec}: the size {n} is too large")))
        .transpose()?;
    let params = Params::new(kind, size, seed).map_err(|e| format!("{spec}: {e}"))?;
    Ok(Scene {
        source: spec.to_string(),
        ..params.scene()
    })
}

/// A scene of `prims`, one default material, and a camera framing them.
pub fn scene_of(source: String, prims: Vec<Primitive>) -> Scene {
    let mut scene = Scene {
        materials: vec![Material::default()],
        source,
        ..Scene::default()
    };
    for p in prims {
        scene.push(p, 0);
    }
    // The framing of any scene without a camera, at a test scene's size.
    scene.camera = Some(CameraSpec {
        width: 256,
        height: 256,
        ..scene.default_camera()
    });
    scene
}

/// A closed UV-sphere triangle mesh of about `n` triangles: every edge is shared
/// by two triangles and every pole vertex by many, so rays through edges and
/// vertices are common.
pub fn uv_sphere_mesh(center: Vec3, radius: f32, n: usize) -> Vec<Primitive> {
    let rings = ((n as f32 / 2.0).sqrt() as usize).max(3);
    let segments = (n / (2 * rings)).max(3);
    let point = |ring: usize, seg: usize| {
        // The poles exactly, so their fans share one vertex.
        if ring == 0 || ring == rings {
            return center + radius * if ring == 0 { Vec3::Y } else { Vec3::NEG_Y };
        }
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        let phi = std::f32::consts::TAU * (seg % segments) as f32 / segments as f32;
        center + radius * Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    let mut tris = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b, c, d) = (point(r, s), point(r, s + 1), point(r + 1, s), point(r + 1, s + 1));
            if r > 0 {
                tris.push(Primitive::Triangle(Triangle::new(a, b, c)));
            }
            if r + 1 < rings {
                tris.push(Primitive::Triangle(Triangle::new(b, d, c)));
            }
        }
    }
    tris
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `gen:` spec is generated, anything else is read as a file, whose
    /// error names it.
    #[test]
    fn a_spec_is_generated_or_read_from_its_file() {
        let generated = load_spec("gen:triangles:50:2").unwrap();
        let in_code = from_spec("gen:triangles:50:2").unwrap().unwrap();
        assert_eq!(generated.primitives, in_code.primitives);
        let read = load_spec("scenes/lecture.toml").unwrap();
        assert!(!read.primitives.is_empty());
        let missing = load_spec("no/such/scene.nff").unwrap_err();
        assert!(missing.contains("no/such/scene.nff"), "{missing}");
        let unknown = load_spec("gen:no-such-scene").unwrap_err();
        assert!(unknown.contains("gen:no-such-scene"), "{unknown}");
    }

    #[test]
    fn every_named_scene_is_built_seeded_and_framed() {
        for name in NAMES {
            let a = by_name(name, 200, 1).unwrap();
            let b = by_name(name, 200, 1).unwrap();
            assert_eq!(a.primitives, b.primitives, "{name} is seeded");
            assert!(
                a.primitives.len() >= 100 && a.primitives.len() <= 210,
                "{name}: {}",
                a.primitives.len()
            );
            assert!(a.camera.unwrap().camera().is_ok(), "{name}");
        }
        assert!(by_name("nothing", 10, 1).is_none());
    }

    #[test]
    fn specs_name_generated_scenes_or_say_what_is_wrong() {
        assert!(from_spec("scenes/balls.nff").is_none());
        let s = from_spec("gen:spheres:50:3").unwrap().unwrap();
        assert_eq!(s.primitives.len(), 50);
        assert_eq!(s.primitives, by_name("spheres", 50, 3).unwrap().primitives);
        assert_eq!(
            from_spec("gen:mesh").unwrap().unwrap().source,
            "generated:mesh:1000:1"
        );
        let err = |spec: &str| from_spec(spec).unwrap().unwrap_err();
        assert!(err("gen:cubes").contains("unknown generated scene `cubes`"));
        assert!(err("gen:spheres:many").contains("the primitive count must be a whole number"));
        assert!(err("gen:spheres:5:1:2").contains("expected gen:NAME[:N[:SEED]]"));
    }

    #[test]
    fn specs_also_name_the_kinds_of_raypack_gen() {
        // Size and seed as `raypack gen` takes them, defaults included.
        let rings = from_spec("gen:rings:1").unwrap().unwrap();
        assert_eq!(rings.primitives.len(), 61);
        assert!(rings.camera.is_some() && rings.lights.len() == 3);
        let tetra = from_spec("gen:tetra").unwrap().unwrap();
        assert_eq!(tetra.primitives.len(), 4096);
        let mount = from_spec("gen:mount:1:4").unwrap().unwrap();
        assert_eq!(mount.primitives.len(), 132);
        // One sphereflake, the SPD's, by either of its names: 91 spheres and the floor.
        let flake = from_spec("gen:sphereflake:2").unwrap().unwrap();
        assert_eq!(flake.primitives.len(), 92);
        assert_eq!(
            flake.primitives,
            from_spec("gen:balls:2").unwrap().unwrap().primitives
        );
        let err = |spec: &str| from_spec(spec).unwrap().unwrap_err();
        assert!(err("gen:tree:99").contains("--size 99 is out of range"));
        assert!(err("gen:tree:3:2").contains("tree is not random"));
        assert!(err("gen:tree:x").contains("the size must be a whole number"));
        assert!(err("gen:cubes").contains("or of `raypack gen`: sphereflake, tetra"));
    }

    #[test]
    fn the_mesh_is_closed() {
        // Every edge of a closed mesh is shared by exactly two triangles.
        let mut edges = std::collections::HashMap::new();
        for p in uv_sphere_mesh(Vec3::ZERO, 1.0, 500) {
            let Primitive::Triangle(t) = p else { unreachable!() };
            let v = t.vertices().map(|v| v.to_array().map(f32::to_bits));
            for (a, b) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
                *edges.entry(if a < b { (a, b) } else { (b, a) }).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&k| k == 2));
    }
}
