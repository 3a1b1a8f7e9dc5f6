//! Property tests (proptest) over random scenes whose coordinates include NaN,
//! infinities and huge values (1e30, 1e38, `f32::MAX`), issue 21:
//!
//! - built directly from primitives (the constructors that check refuse what
//!   they refuse), the BVH build terminates and tracing never panics, records
//!   only finite hits inside the ray's interval, and the packet traversal
//!   agrees with the single-ray one lane by lane;
//! - written as NFF or TOML text, the readers either refuse the file with a
//!   `file:line` error (non-finite numbers, and numbers beyond `f32`, are
//!   refused today) or load it, and what they load builds and traces as above.

use glam::{Mat4, Vec3};
use proptest::prelude::*;
use raypack::accel::{Accel, Bvh};
use raypack::geometry::plane::Plane;
use raypack::geometry::{Cone, Polygon, Primitive, Sphere, Transformed, Triangle};
use raypack::packet::RayPacket8;
use raypack::ray::{NO_HIT, Ray};
use raypack::scene::{self, nff};
use raypack::simd::SimdFloat;
use std::path::Path;

/// The hostile values, and ordinary ones so that some primitives are usable.
const SPECIAL: [f32; 12] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    1e30,
    -1e30,
    1e38,
    -1e38,
    f32::MAX,
    f32::MIN,
    f32::MIN_POSITIVE,
    0.0,
    -0.0,
];

/// A coordinate: ordinary in about 2 of 3 draws, else one of [`SPECIAL`].
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        2 => -10.0f32..10.0,
        1 => proptest::sample::select(&SPECIAL[..]),
    ]
}

fn point() -> impl Strategy<Value = Vec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Any primitive the constructors accept from hostile coordinates (None where
/// a checking constructor refuses them).
fn primitive() -> impl Strategy<Value = Option<Primitive>> {
    prop_oneof![
        (point(), coord()).prop_map(|(c, r)| Some(Primitive::Sphere(Sphere::new(c, r)))),
        (point(), point(), point()).prop_map(|(a, b, c)| Some(Primitive::Triangle(Triangle::new(a, b, c)))),
        proptest::collection::vec(point(), 3..6).prop_map(|v| Polygon::new(&v).ok().map(Primitive::Polygon)),
        (point(), coord(), point(), coord())
            .prop_map(|(b, rb, a, ra)| Cone::new(b, rb, a, ra).ok().map(Primitive::Cone)),
        (coord(), coord(), coord(), coord())
            .prop_map(|(a, b, c, d)| Plane::implicit(a, b, c, d).ok().map(Primitive::Plane)),
        (point(), point(), point())
            .prop_map(|(q, i, j)| Plane::parametric(q, i, j).ok().map(Primitive::Plane)),
        (point(), coord(), point()).prop_map(|(c, r, t)| {
            let m = Mat4::from_translation(t) * Mat4::from_scale(Vec3::splat(r));
            Transformed::new(Primitive::Sphere(Sphere::new(c, 1.0)), m)
                .ok()
                .map(|t| Primitive::Transformed(Box::new(t)))
        }),
    ]
}

fn ray() -> impl Strategy<Value = Ray> {
    (point(), point(), coord(), coord()).prop_map(|(o, d, t0, t1)| {
        let dir = d.try_normalize().unwrap_or(d);
        Ray::new(
            o,
            dir,
            t0.abs().min(1.0),
            if t1.is_nan() { t1 } else { f32::INFINITY },
        )
    })
}

/// Build the BVH over `prims` and trace `rays` every way; the checks of the module doc.
fn build_and_trace(prims: &[Primitive], rays: &[Ray]) {
    let bvh = Bvh::new(prims);
    for chunk in rays.chunks(8) {
        let packet = RayPacket8::from_rays(chunk);
        let hits = bvh.intersect_packet(&packet);
        let occluded = bvh.occluded_packet(&packet).bitmask();
        for (i, ray) in chunk.iter().enumerate() {
            let hit = bvh.intersect(ray);
            let lane = hits.hit(i);
            assert_eq!(lane.prim, hit.prim, "lane {i} of {ray:?}: {lane:?} vs {hit:?}");
            if hit.prim != NO_HIT {
                assert!((hit.prim as usize) < prims.len());
                assert!(
                    hit.t.is_finite() && hit.t >= ray.t_min && hit.t <= ray.t_max,
                    "{hit:?} for {ray:?}"
                );
            }
            // Any-hit answers must at least not panic; a nearest hit implies occlusion.
            let any = bvh.occluded(ray);
            assert!(!hit.is_hit() || any, "{ray:?} hits {hit:?} but is not occluded");
            assert!(!hit.is_hit() || occluded >> i & 1 == 1, "lane {i}: {ray:?}");
        }
    }
}

/// Rays at the scene from outside and along the axes, so that some hit.
fn aimed_rays(prims: &[Primitive]) -> Vec<Ray> {
    let mut rays = Vec::new();
    for p in prims.iter().filter_map(Primitive::bounds).take(8) {
        let from = Vec3::new(0.5, 0.25, 40.0);
        if let Some(dir) = (p.center() - from).try_normalize() {
            rays.push(Ray::unbounded(from, dir));
        }
    }
    for dir in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
        rays.push(Ray::unbounded(Vec3::ZERO, dir));
    }
    rays
}

/// A number as a scene file might spell it.
fn spelled(x: f32) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{x:e}")
    }
}

/// A text number: one of [`coord`], or one beyond `f32` (1e39).
fn text_number() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => coord().prop_map(spelled),
        1 => proptest::sample::select(&["1e39", "-1e39", "1e400"][..]).prop_map(String::from),
    ]
}

fn numbers(n: usize) -> impl Strategy<Value = Vec<String>> {
    proptest::collection::vec(text_number(), n)
}

/// One NFF entity with hostile numbers.
fn nff_entity() -> impl Strategy<Value = String> {
    prop_oneof![
        numbers(4).prop_map(|v| format!("s {}\n", v.join(" "))),
        numbers(9).prop_map(|v| format!(
            "p 3\n{}\n{}\n{}\n",
            v[..3].join(" "),
            v[3..6].join(" "),
            v[6..].join(" ")
        )),
        numbers(18).prop_map(|v| {
            let rows: Vec<String> = v.chunks(6).map(|r| r.join(" ")).collect();
            format!("pp 3\n{}\n", rows.join("\n"))
        }),
        numbers(8).prop_map(|v| format!("c\n{}\n{}\n", v[..4].join(" "), v[4..].join(" "))),
        numbers(3).prop_map(|v| format!("l {}\n", v.join(" "))),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn hostile_primitives_build_and_trace(
        prims in proptest::collection::vec(primitive(), 0..24),
        rays in proptest::collection::vec(ray(), 0..24),
    ) {
        let prims: Vec<Primitive> = prims.into_iter().flatten().collect();
        let mut rays = rays;
        rays.extend(aimed_rays(&prims));
        build_and_trace(&prims, &rays);
    }

    #[test]
    fn hostile_nff_is_refused_at_a_line_or_loads_finite(
        entities in proptest::collection::vec(nff_entity(), 1..12),
    ) {
        let text = format!("s 0 0 0 1\n{}", entities.concat());
        match nff::parse(Path::new("hostile.nff"), text.as_bytes()) {
            Err(e) => {
                let lines = text.lines().count() + 1;
                prop_assert!(e.line.is_some_and(|l| (1..=lines).contains(&l)), "{e}");
                prop_assert!(e.to_string().starts_with("hostile.nff:"), "{e}");
            }
            Ok(scene) => {
                for p in &scene.primitives {
                    if let Some(b) = p.bounds() {
                        prop_assert!(!b.min.is_nan() && !b.max.is_nan(), "{p:?} from\n{text}");
                    }
                }
                let rays = aimed_rays(&scene.primitives);
                build_and_trace(&scene.primitives, &rays);
            }
        }
    }

    #[test]
    fn hostile_toml_is_refused_at_a_line_or_loads(
        centers in proptest::collection::vec(numbers(4), 1..6),
    ) {
        let mut text = String::new();
        for v in &centers {
            // TOML spells infinities `inf`/`-inf` and NaN `nan`, as `spelled` does.
            text += &format!(
                "[[objects]]\ntype = \"sphere\"\ncenter = [{}, {}, {}]\nradius = {}\n",
                v[0], v[1], v[2], v[3].trim_start_matches('-')
            );
        }
        match scene::parse(Path::new("hostile.toml"), text.as_bytes()) {
            Err(e) => prop_assert!(e.line.is_some(), "{e}"),
            Ok(scene) => build_and_trace(&scene.primitives, &aimed_rays(&scene.primitives)),
        }
    }
}
