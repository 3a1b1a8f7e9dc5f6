//! Every packet kernel agrees with its scalar twin lane by lane on 10⁶ seeded
//! random rays (inactive lanes and earlier hits included), and the projected
//! barycentric triangle test agrees with the lecture's half-plane test.

use crate::support::kernel::{assert_packet_matches_scalar, random_ray};
use glam::{Mat4, Quat, Vec3};
use raypack::bench::kernels::star_polygon;
use raypack::geometry::triangle::intersect_half_plane;
use raypack::geometry::{Intersect, Plane, Polygon, Primitive, Sphere, Transformed, Triangle, TriangleTest};
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;
use wide::{f32x4, f32x8, f32x16};

const N: usize = 1_000_000;

fn agree<K: Intersect>(name: &str, shape: &K, lo: Vec3, hi: Vec3, seed: u64) {
    let stats = assert_packet_matches_scalar::<K, f32x8>(shape, lo, hi, N, seed);
    // A test that never hits proves nothing: insist on a healthy mix.
    let rate = stats.hits as f64 / stats.active as f64;
    assert!(
        (0.05..0.95).contains(&rate),
        "{name}: hit rate {rate} is too extreme to be a test"
    );
}

#[test]
fn sphere_packet_matches_scalar() {
    agree(
        "sphere",
        &Sphere::new(Vec3::new(0.5, -0.25, 1.0), 1.5),
        Vec3::splat(-1.0),
        Vec3::new(2.0, 1.25, 2.5),
        1,
    );
}

#[test]
fn implicit_plane_packet_matches_scalar() {
    let plane = Plane::implicit(0.3, -0.2, 1.0, 0.4).unwrap();
    agree("implicit plane", &plane, Vec3::splat(-2.0), Vec3::splat(2.0), 2);
}

#[test]
fn point_normal_plane_packet_matches_scalar() {
    let plane = Plane::point_normal(Vec3::new(0.1, 0.2, -0.3), Vec3::new(-0.5, 1.0, 0.25)).unwrap();
    agree(
        "point-normal plane",
        &plane,
        Vec3::splat(-2.0),
        Vec3::splat(2.0),
        3,
    );
}

#[test]
fn parametric_plane_packet_matches_scalar() {
    let plane = Plane::parametric(
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(1.0, 0.2, 0.1),
        Vec3::new(-0.3, 0.1, 1.0),
    )
    .unwrap();
    agree("parametric plane", &plane, Vec3::splat(-2.0), Vec3::splat(2.0), 4);
}

#[test]
fn triangle_packet_matches_scalar() {
    // One triangle per dominant axis, so every projection is exercised.
    let triangles = [
        Triangle::new(
            Vec3::new(0.1, -1.0, -1.0),
            Vec3::new(-0.2, 1.0, -0.5),
            Vec3::new(0.0, 0.0, 1.0),
        ),
        Triangle::new(
            Vec3::new(-1.0, 0.1, -1.0),
            Vec3::new(1.0, 0.0, -0.5),
            Vec3::new(0.0, -0.2, 1.0),
        ),
        Triangle::new(
            Vec3::new(-1.0, -1.0, 0.2),
            Vec3::new(1.0, -0.5, 0.0),
            Vec3::new(0.0, 1.0, -0.1),
        ),
    ];
    for (k, tri) in triangles.iter().enumerate() {
        agree(
            &format!("triangle {k}"),
            tri,
            Vec3::splat(-1.0),
            Vec3::splat(1.0),
            10 + k as u64,
        );
    }
}

#[test]
fn polygon_packet_matches_scalar() {
    // Both kernels: the crossing test, and the watertight pieces.
    for test in [TriangleTest::Barycentric, TriangleTest::Watertight] {
        let mut star = star_polygon();
        star.set_test(test);
        agree(
            &format!("star polygon, {test:?}"),
            &star,
            Vec3::splat(-1.0),
            Vec3::splat(1.0),
            20,
        );
        // A concave L-shape in a tilted plane.
        let l_shape = crate::L_SHAPE.map(|(x, y)| Vec3::new(x, 0.5 * x - 0.25 * y, y));
        let mut l = Polygon::new(&l_shape).unwrap();
        l.set_test(test);
        agree(
            &format!("L polygon, {test:?}"),
            &l,
            Vec3::ZERO,
            Vec3::splat(2.0),
            21,
        );
    }
}

#[test]
fn transformed_packet_matches_scalar() {
    let m = Mat4::from_scale_rotation_translation(
        Vec3::new(2.0, 0.5, 1.0),
        Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1),
        Vec3::new(0.5, 0.0, -0.5),
    );
    let ellipsoid = Transformed::new(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)), m).unwrap();
    agree("ellipsoid", &ellipsoid, Vec3::splat(-2.0), Vec3::splat(2.0), 30);
    let sheared = Mat4::from_cols_array(&[
        1.0, 0.0, 0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 0.3, 1.0, 0.0, 0.2, 0.1, 0.0, 1.0,
    ]);
    let triangle = Triangle::new(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.1),
        Vec3::new(0.0, 1.0, 0.0),
    );
    let sheared_triangle = Transformed::new(Primitive::Triangle(triangle), sheared).unwrap();
    agree(
        "sheared triangle",
        &sheared_triangle,
        Vec3::splat(-1.5),
        Vec3::splat(1.5),
        31,
    );
}

#[test]
fn packet_width_is_a_type_parameter() {
    // The same kernels instantiated 4 and 16 wide agree with the scalar kernels too.
    let sphere = Sphere::new(Vec3::ZERO, 1.0);
    let tri = Triangle::new(
        Vec3::new(-1.0, -1.0, 0.2),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, -0.2),
    );
    let lo = Vec3::splat(-1.0);
    let hi = Vec3::splat(1.0);
    assert_packet_matches_scalar::<_, f32x4>(&sphere, lo, hi, 100_000, 40);
    assert_packet_matches_scalar::<_, f32x16>(&sphere, lo, hi, 100_000, 41);
    assert_packet_matches_scalar::<_, f32x4>(&tri, lo, hi, 100_000, 42);
    assert_packet_matches_scalar::<_, f32x16>(&tri, lo, hi, 100_000, 43);
    let star = star_polygon();
    assert_packet_matches_scalar::<_, f32x16>(&star, lo, hi, 100_000, 44);
}

#[test]
fn projected_barycentric_agrees_with_half_plane_test() {
    let mut rng = Rng::new(50);
    let (lo, hi) = (Vec3::splat(-1.0), Vec3::splat(1.0));
    let (mut compared, mut hits) = (0, 0);
    // A fresh random triangle every 64 rays.
    for _ in 0..N / 64 {
        let verts = [rng.point_in(lo, hi), rng.point_in(lo, hi), rng.point_in(lo, hi)];
        let tri = Triangle::new(verts[0], verts[1], verts[2]);
        for k in 0..64 {
            // Half the rays aim at points around the triangle, half are random.
            let ray = if k % 2 == 0 {
                let (beta, gamma) = (rng.range(-0.2, 1.0), rng.range(-0.2, 1.0));
                let target = verts[0] + beta * (verts[1] - verts[0]) + gamma * (verts[2] - verts[0]);
                let origin = 4.0 * rng.unit_vector();
                Ray::unbounded(origin, (target - origin).normalize())
            } else {
                random_ray(&mut rng, lo, hi)
            };
            // Within rounding distance of an edge the two tests may legitimately
            // round to different sides: skip those rays.
            if near_edge(&ray, verts) {
                continue;
            }
            let mut hit = Hit::none(&ray);
            let projected = tri.intersect(&ray, 0, &mut hit).then_some(hit.t);
            let reference = intersect_half_plane(verts[0], verts[1], verts[2], &ray);
            compared += 1;
            match (projected, reference) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    // t is ill-conditioned for grazing rays: scale the tolerance by 1/cos.
                    let normal = (verts[1] - verts[0]).cross(verts[2] - verts[0]).normalize();
                    let cos = normal.dot(ray.dir).abs();
                    let tolerance = 1e-5 * a.abs().max(1.0) / cos;
                    assert!((a - b).abs() <= tolerance, "t differs: {a} vs {b} for {ray:?}");
                }
                (None, None) => {}
                _ => panic!(
                    "tests disagree on {ray:?}, {verts:?}: projected {projected:?}, half-plane {reference:?}"
                ),
            }
        }
    }
    assert!(
        compared > N / 2 && hits > compared / 10,
        "compared {compared}, hits {hits}"
    );
}

/// Whether the ray grazes the triangle's plane, or its plane hit lies within
/// rounding distance of the triangle's boundary or of the ray's interval ends
/// (computed in double precision).
fn near_edge(ray: &Ray, verts: [Vec3; 3]) -> bool {
    let [a, b, c] = verts.map(|v| v.as_dvec3());
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let n = (b - a).cross(c - a);
    let denom = n.dot(d);
    let cos = denom.abs() / n.length();
    if n.length() < 1e-3 || cos < 1e-3 {
        return true;
    }
    let t = n.dot(a - o) / denom;
    let p = o + t * d;
    let area = n.length_squared();
    let beta = (p - a).cross(c - a).dot(n) / area;
    let gamma = (b - a).cross(p - a).dot(n) / area;
    let alpha = 1.0 - beta - gamma;
    let near_end = [ray.t_min as f64, ray.t_max as f64]
        .iter()
        .any(|&end| (t - end).abs() < 1e-4 * t.abs().max(1.0));
    // The hit point's rounding error grows as the ray grazes the plane.
    let margin = 1e-4 + 1e-5 / cos;
    [alpha, beta, gamma].iter().any(|x| x.abs() < margin) || near_end
}
