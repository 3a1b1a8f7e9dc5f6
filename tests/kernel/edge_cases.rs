//! Hand-made cases for every kernel: tangent and grazing rays, origins inside,
//! parallel rays, degenerate shapes, exact edge and vertex hits, concave notches,
//! zero direction components, NaN/inf input, and the transformed sphere checked
//! against the analytic ellipsoid. Each case runs the scalar kernel and the
//! packet kernel (all eight lanes) and expects the same answer from both.

use crate::support::kernel::assert_poisoned_rays_miss;
use glam::{DVec3, Mat4, Quat, Vec3};
use raypack::bench::kernels::star_polygon;
use raypack::geometry::{
    GeometryError, Intersect, Plane, Polygon, Primitive, Sphere, Transformed, Triangle, TriangleTest,
};
use raypack::packet::{HitPacket, RayPacket8};
use raypack::ray::{Hit, Ray};
use raypack::rng::Rng;

/// The hit of `ray` on `shape` by both kernels; panics if they disagree.
fn trace<K: Intersect>(shape: &K, ray: Ray) -> Option<Hit> {
    let mut hit = Hit::none(&ray);
    let scalar = shape.intersect(&ray, 7, &mut hit).then_some(hit);
    let packet = RayPacket8::from_rays(&[ray; 8]);
    let mut hits = HitPacket::none(&packet);
    shape.intersect_packet(&packet, 7, &mut hits);
    for lane in 0..8 {
        let h = hits.hit(lane);
        match scalar {
            Some(s) => assert!(
                h.prim == 7 && h.t == s.t,
                "lane {lane}: packet {h:?} vs scalar {s:?}"
            ),
            None => assert!(h.prim != 7, "lane {lane}: packet hit {h:?}, scalar missed"),
        }
    }
    scalar
}

fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
    Ray::unbounded(Vec3::from(o), Vec3::from(d).normalize())
}

fn assert_t(hit: Option<Hit>, t: f32) {
    let h = hit.unwrap_or_else(|| panic!("expected a hit at t = {t}"));
    assert!(
        (h.t - t).abs() <= 1e-5 * t.abs().max(1.0),
        "t = {} expected {t}",
        h.t
    );
}

// ---- sphere -------------------------------------------------------------------

#[test]
fn sphere_front_hit_tangent_and_grazing() {
    let s = Sphere::new(Vec3::ZERO, 1.0);
    assert_t(trace(&s, ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0])), 4.0);
    // Exactly tangent: D = 0, the single root counts as a hit.
    assert_t(trace(&s, ray([1.0, 0.0, -5.0], [0.0, 0.0, 1.0])), 5.0);
    // Grazing just outside misses, just inside hits near the tangent point.
    assert!(trace(&s, ray([1.0001, 0.0, -5.0], [0.0, 0.0, 1.0])).is_none());
    let inside = trace(&s, ray([0.9999, 0.0, -5.0], [0.0, 0.0, 1.0])).expect("grazing hit");
    assert!((inside.t - 5.0).abs() < 0.02);
    // Behind the ray: no hit.
    assert!(trace(&s, ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0])).is_none());
}

#[test]
fn sphere_origin_inside_hits_the_far_root() {
    let s = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0);
    assert_t(trace(&s, ray([1.0, 2.0, 3.0], [0.0, 1.0, 0.0])), 2.0);
    assert_t(trace(&s, ray([1.0, 2.0, 4.0], [0.0, 0.0, -1.0])), 3.0);
    // On the surface leaving it, with a small t_min: no self-hit.
    let leaving = Ray::new(Vec3::new(1.0, 2.0, 5.0), Vec3::Z, 1e-4, f32::INFINITY);
    assert!(trace(&s, leaving).is_none());
    // On the surface entering it: the far side.
    let entering = Ray::new(Vec3::new(1.0, 2.0, 5.0), -Vec3::Z, 1e-4, f32::INFINITY);
    assert_t(trace(&s, entering), 4.0);
}

#[test]
fn sphere_respects_the_interval_and_earlier_hits() {
    let s = Sphere::new(Vec3::ZERO, 1.0);
    let mut r = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
    r.t_max = 3.9;
    assert!(trace(&s, r).is_none());
    r.t_max = 4.0; // t_max itself is in the interval
    assert_t(trace(&s, r), 4.0);
    r.t_min = 4.5;
    r.t_max = f32::INFINITY;
    assert_t(trace(&s, r), 6.0);
    // An earlier hit at equal t on a lower primitive index wins the tie; a higher one loses.
    let r = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
    let mut hit = Hit {
        t: 4.0,
        prim: 3,
        ..Hit::none(&r)
    };
    assert!(!s.intersect(&r, 7, &mut hit));
    hit.prim = 9;
    assert!(s.intersect(&r, 7, &mut hit) && hit.prim == 7);
}

#[test]
fn sphere_normal_points_outward() {
    let s = Sphere::new(Vec3::new(0.0, 1.0, 0.0), 2.0);
    let r = ray([0.0, 1.0, -5.0], [0.0, 0.0, 1.0]);
    let mut hit = trace(&s, r).unwrap();
    hit.ng = Primitive::Sphere(s).geometric_normal(&r, &hit);
    assert!((hit.ng - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
}

// ---- planes ---------------------------------------------------------------------

fn three_forms_of_z_equals_2() -> [Plane; 3] {
    [
        Plane::implicit(0.0, 0.0, 2.0, -4.0).unwrap(),
        Plane::point_normal(Vec3::new(3.0, -1.0, 2.0), Vec3::new(0.0, 0.0, 5.0)).unwrap(),
        Plane::parametric(Vec3::new(1.0, 1.0, 2.0), Vec3::X, Vec3::Y).unwrap(),
    ]
}

#[test]
fn planes_in_all_three_forms_agree() {
    for p in three_forms_of_z_equals_2() {
        assert_t(trace(&p, ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])), 2.0);
        // Hit from behind too (planes are two-sided for intersection).
        assert_t(trace(&p, ray([0.5, 0.5, 4.0], [0.0, 0.0, -1.0])), 2.0);
        // Oblique, with zero direction components.
        assert_t(
            trace(&p, ray([0.0, 0.0, 0.0], [0.0, 1.0, 1.0])),
            2.0 * 2f32.sqrt(),
        );
        // Pointing away: miss.
        assert!(trace(&p, ray([0.0, 0.0, 0.0], [0.0, 0.0, -1.0])).is_none());
        assert!((p.normal() - Vec3::Z).length() < 1e-6);
    }
}

#[test]
fn rays_parallel_to_a_plane_miss_even_inside_it() {
    for p in three_forms_of_z_equals_2() {
        assert!(trace(&p, ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0])).is_none());
        assert!(trace(&p, ray([0.0, 0.0, 2.0], [1.0, 1.0, 0.0])).is_none());
    }
}

#[test]
fn parametric_plane_reports_its_coordinates() {
    let p = Plane::parametric(
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 4.0),
    )
    .unwrap();
    // The point q + 0.25·i + 0.5·j = (1.5, 0, 2).
    let h = trace(&p, ray([1.5, 3.0, 2.0], [0.0, -1.0, 0.0])).unwrap();
    assert_t(Some(h), 3.0);
    assert!((h.u - 0.25).abs() < 1e-6 && (h.v - 0.5).abs() < 1e-6, "{h:?}");
}

#[test]
fn degenerate_planes_are_errors() {
    assert_eq!(
        Plane::implicit(0.0, 0.0, 0.0, 1.0),
        Err(GeometryError::DegeneratePlane)
    );
    assert_eq!(
        Plane::point_normal(Vec3::ZERO, Vec3::ZERO),
        Err(GeometryError::DegeneratePlane)
    );
    assert_eq!(
        Plane::parametric(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X),
        Err(GeometryError::DegeneratePlane)
    );
    assert_eq!(
        Plane::implicit(f32::NAN, 0.0, 1.0, 1.0),
        Err(GeometryError::NotFinite)
    );
}

// ---- triangles -----------------------------------------------------------------

fn unit_triangle() -> Triangle {
    Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y)
}

#[test]
fn triangle_interior_edges_and_vertices_hit() {
    let t = unit_triangle();
    let down = [0.0, 0.0, -1.0];
    let h = trace(&t, ray([0.25, 0.5, 1.0], down)).unwrap();
    assert_t(Some(h), 1.0);
    assert!(
        (h.u - 0.25).abs() < 1e-6 && (h.v - 0.5).abs() < 1e-6,
        "barycentrics {h:?}"
    );
    // Exactly on each edge and each vertex (exactly representable points).
    for p in [
        [0.5, 0.0],
        [0.0, 0.5],
        [0.5, 0.5],
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
    ] {
        assert_t(trace(&t, ray([p[0], p[1], 1.0], down)), 1.0);
    }
    // Just outside each edge.
    for p in [[0.5, -1e-4], [-1e-4, 0.5], [0.5 + 1e-4, 0.5 + 1e-4]] {
        assert!(
            trace(&t, ray([p[0], p[1], 1.0], down)).is_none(),
            "{p:?} is outside"
        );
    }
}

#[test]
fn triangle_hits_from_behind_and_with_zero_direction_components() {
    let t = Triangle::new(
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    );
    assert_t(trace(&t, ray([0.2, 0.2, 3.0], [0.0, 0.0, -1.0])), 2.0);
    assert_t(trace(&t, ray([0.2, 0.2, -3.0], [0.0, 0.0, 1.0])), 4.0);
    // A vertical triangle (dominant axis x) hit along x.
    let side = Triangle::new(Vec3::ZERO, Vec3::Y, Vec3::Z);
    assert_t(trace(&side, ray([-2.0, 0.25, 0.25], [1.0, 0.0, 0.0])), 2.0);
    assert!((side.normal() - Vec3::X).length() < 1e-6);
    assert!((unit_triangle().normal() - Vec3::Z).length() < 1e-6);
}

#[test]
fn triangle_parallel_rays_miss() {
    let t = unit_triangle();
    assert!(trace(&t, ray([0.2, 0.2, 0.0], [1.0, 0.0, 0.0])).is_none());
    assert!(trace(&t, ray([-1.0, 0.2, 0.5], [1.0, 0.0, 0.0])).is_none());
}

#[test]
fn degenerate_triangles_are_never_hit() {
    let degenerate = [
        Triangle::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X), // collinear
        Triangle::new(Vec3::ZERO, Vec3::ZERO, Vec3::Y),    // repeated vertex
        Triangle::new(Vec3::ONE, Vec3::ONE, Vec3::ONE),    // a point
        Triangle::new(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y), // NaN vertex
    ];
    for t in &degenerate {
        assert!(t.is_degenerate());
        assert!(t.bounds().is_none());
        for d in [[0.0, 0.0, -1.0], [0.0, -1.0, 0.0], [-1.0, 0.0, 0.0]] {
            assert!(trace(t, ray([0.5, 0.5, 0.5], d)).is_none());
            assert!(trace(t, ray([0.0, 0.0, 1.0], d)).is_none());
        }
    }
}

// ---- polygons ------------------------------------------------------------------

/// The L in the plane z = 0, under `test`'s kernels.
fn l_shape(test: TriangleTest) -> Polygon {
    let mut l = Polygon::new(&crate::L_SHAPE.map(|(x, y)| Vec3::new(x, y, 0.0))).unwrap();
    l.set_test(test);
    l
}

/// Both polygon kernels: the crossing test, and the watertight pieces.
const POLYGON_TESTS: [TriangleTest; 2] = [TriangleTest::Barycentric, TriangleTest::Watertight];

#[test]
fn concave_polygon_notch_is_a_miss() {
    for test in POLYGON_TESTS {
        let l = l_shape(test);
        let down = [0.0, 0.0, -1.0];
        assert_t(trace(&l, ray([0.5, 0.5, 1.0], down)), 1.0);
        assert_t(trace(&l, ray([1.5, 0.5, 1.0], down)), 1.0);
        assert_t(trace(&l, ray([0.5, 1.5, 1.0], down)), 1.0);
        // Through the notch.
        assert!(trace(&l, ray([1.5, 1.5, 1.0], down)).is_none(), "{test:?}");
        // The crossing ray from a point in the notch passes a reflex vertex at y = 1.
        assert!(trace(&l, ray([1.5, 1.0 + 1e-3, 1.0], down)).is_none(), "{test:?}");
        assert_t(trace(&l, ray([0.5, 1.0, 1.0], down)), 1.0);
        // Outside entirely.
        assert!(trace(&l, ray([2.5, 0.5, 1.0], down)).is_none(), "{test:?}");
        assert!((l.normal() - Vec3::Z).length() < 1e-6);
    }
}

#[test]
fn star_polygon_points_hit_and_notches_miss() {
    for test in POLYGON_TESTS {
        let mut star = star_polygon(); // tips at radius 1, notches at radius 0.4, plane z = 0.3x
        star.set_test(test);
        let a_tip = 0.0f32; // a tip direction
        let a_notch = std::f32::consts::TAU / 20.0; // halfway between a tip and a notch vertex
        for (angle, r, inside) in [
            (a_tip, 0.9, true),
            (a_notch, 0.8, false),
            (a_notch, 0.2, true),
            (0.0, 0.0, true),
        ] {
            let (x, y) = (r * angle.cos(), r * angle.sin());
            let hit = trace(&star, ray([x, y, 0.3 * x + 2.0], [0.0, 0.0, -1.0]));
            assert_eq!(hit.is_some(), inside, "{test:?}: angle {angle} r {r}");
        }
    }
}

#[test]
fn polygon_pieces_cover_what_the_crossing_test_hits() {
    // The watertight pieces are the polygon's surface cut on its plane: on
    // random rays through its box, they hit where the crossing test hits, at
    // the same t, except within rounding of an edge.
    let mut rng = Rng::new(41);
    let (mut star, mut hits) = (star_polygon(), 0);
    for _ in 0..20_000 {
        let target = Vec3::new(rng.range(-1.2, 1.2), rng.range(-1.2, 1.2), 0.0);
        let target = target + Vec3::Z * (0.3 * target.x);
        let origin = target + 3.0 * rng.unit_vector();
        let r = Ray::unbounded(origin, (target - origin).normalize());
        star.set_test(TriangleTest::Barycentric);
        let crossing = trace(&star, r);
        star.set_test(TriangleTest::Watertight);
        let pieces = trace(&star, r);
        let near_edge = star_edge_distance(target) < 1e-4;
        match (crossing, pieces) {
            (Some(c), Some(p)) => {
                hits += 1;
                // The same plane up to the vertices' rounding: the two t may
                // differ by that rounding over the ray's slope to the plane.
                let slope = r.dir.dot(star.normal()).abs();
                assert!(
                    (c.t - p.t).abs() * slope <= 1e-6 * c.t,
                    "{r:?}: t {} vs {}",
                    c.t,
                    p.t
                );
            }
            (None, None) => {}
            (c, p) => assert!(near_edge, "{r:?}: crossing {c:?}, pieces {p:?}"),
        }
    }
    assert!(
        (2_000..18_000).contains(&hits),
        "{hits} hits: too few or too many to test anything"
    );
}

/// The distance in (x, y) from `p` to the nearest edge of [`star_polygon`].
fn star_edge_distance(p: Vec3) -> f32 {
    let v = star_polygon().vertices().to_vec();
    let q = p.truncate();
    (0..v.len())
        .map(|i| {
            let (a, b) = (v[i].truncate(), v[(i + 1) % v.len()].truncate());
            let s = ((q - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            (q - (a + s * (b - a))).length()
        })
        .fold(f32::INFINITY, f32::min)
}

#[test]
fn polygon_validation_errors() {
    assert_eq!(
        Polygon::new(&[Vec3::ZERO, Vec3::X]),
        Err(GeometryError::TooFewVertices(2))
    );
    let collinear = [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X, Vec3::Y];
    assert_eq!(Polygon::new(&collinear), Err(GeometryError::CollinearVertices));
    assert_eq!(
        Polygon::new(&[Vec3::ZERO, Vec3::X, Vec3::INFINITY]),
        Err(GeometryError::NotFinite)
    );
}

#[test]
fn polygon_parallel_rays_miss() {
    for test in POLYGON_TESTS {
        let l = l_shape(test);
        assert!(
            trace(&l, ray([0.5, 0.5, 0.0], [1.0, 0.0, 0.0])).is_none(),
            "{test:?}"
        );
    }
}

// ---- NaN / inf -----------------------------------------------------------------

#[test]
fn nan_and_infinite_rays_miss_on_every_kernel() {
    let sphere = Sphere::new(Vec3::ZERO, 1.0);
    assert_poisoned_rays_miss("sphere", &sphere);
    for p in three_forms_of_z_equals_2() {
        assert_poisoned_rays_miss("plane", &p);
    }
    let tri = Triangle::new(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    );
    assert_poisoned_rays_miss("triangle", &tri);
    assert_poisoned_rays_miss("polygon", &star_polygon());
    let ellipsoid = Transformed::new(
        Primitive::Sphere(sphere),
        Mat4::from_scale(Vec3::new(2.0, 1.0, 0.5)),
    )
    .unwrap();
    assert_poisoned_rays_miss("transformed", &ellipsoid);
}

// ---- transformed objects ---------------------------------------------------------

/// The ray's nearest hit on the ellipsoid `R·diag(a)·unit sphere + c`, solved
/// directly in double precision.
fn analytic_ellipsoid(ray: &Ray, axes: DVec3, rotation: glam::DQuat, c: DVec3) -> Option<(f64, DVec3)> {
    let inv = rotation.inverse();
    let o = inv * (ray.origin.as_dvec3() - c) / axes;
    let d = inv * ray.dir.as_dvec3() / axes;
    let (a, b, cc) = (d.dot(d), 2.0 * o.dot(d), o.dot(o) - 1.0);
    let disc = b * b - 4.0 * a * cc;
    if disc < 0.0 {
        return None;
    }
    let (t0, t1) = ((-b - disc.sqrt()) / (2.0 * a), (-b + disc.sqrt()) / (2.0 * a));
    let t = if t0 >= ray.t_min as f64 { t0 } else { t1 };
    if t < ray.t_min as f64 {
        return None;
    }
    // Gradient of the implicit function, in world space.
    let p_local = o + t * d;
    let normal = (rotation * (p_local / axes)).normalize();
    Some((t, normal))
}

#[test]
fn transformed_sphere_is_the_analytic_ellipsoid() {
    let axes = DVec3::new(2.0, 0.5, 1.0);
    let rotation = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.4, -0.3, 0.9);
    let center = DVec3::new(0.5, -1.0, 0.25);
    let m = Mat4::from_scale_rotation_translation(axes.as_vec3(), rotation.as_quat(), center.as_vec3());
    let ellipsoid = Transformed::new(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)), m).unwrap();
    let prim = Primitive::Transformed(Box::new(ellipsoid.clone()));
    let mut rng = Rng::new(60);
    let (mut hits, mut compared) = (0, 0);
    for _ in 0..100_000 {
        let origin = center.as_vec3() + 5.0 * rng.unit_vector();
        let target = center.as_vec3() + rng.point_in(Vec3::splat(-2.0), Vec3::splat(2.0));
        let r = Ray::unbounded(origin, (target - origin).normalize());
        let ours = trace(&ellipsoid, r);
        let exact = analytic_ellipsoid(&r, axes, rotation, center);
        // Skip near-tangent rays, where rounding decides hit or miss.
        if let Some((t, n)) = exact
            && n.dot(r.dir.as_dvec3()).abs() < 1e-3
        {
            let _ = t;
            continue;
        }
        compared += 1;
        match (ours, exact) {
            (Some(h), Some((t, n))) => {
                hits += 1;
                assert!((h.t as f64 - t).abs() <= 1e-4 * t, "t {} vs {t}", h.t);
                let ng = prim.geometric_normal(&r, &h).as_dvec3();
                assert!((ng - n).length() < 1e-3, "normal {ng} vs {n}");
            }
            (None, None) => {}
            _ => panic!("ellipsoid disagrees on {r:?}: ours {ours:?}, exact {exact:?}"),
        }
    }
    assert!(
        compared > 90_000 && hits > compared / 5,
        "{compared} compared, {hits} hits"
    );
}

#[test]
fn transformed_hits_report_world_space_t() {
    // A unit sphere moved to (0, 0, 10) and scaled by 3: the front is at z = 7.
    let m = Mat4::from_translation(Vec3::new(0.0, 0.0, 10.0)) * Mat4::from_scale(Vec3::splat(3.0));
    let s = Transformed::new(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)), m).unwrap();
    assert_t(trace(&s, ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])), 7.0);
    // A rotated unit triangle: barycentrics survive the transform.
    let rot = Mat4::from_quat(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2));
    let t = Transformed::new(Primitive::Triangle(unit_triangle()), rot).unwrap();
    // The triangle now spans x and z (y → z): the point (0.25, 0, 0.5) is inside.
    let h = trace(&t, ray([0.25, -2.0, 0.5], [0.0, 1.0, 0.0])).unwrap();
    assert_t(Some(h), 2.0);
    assert!((h.u - 0.25).abs() < 1e-5 && (h.v - 0.5).abs() < 1e-5);
}

#[test]
fn singular_or_projective_transforms_are_errors() {
    let sphere = Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0));
    let flat = Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0));
    assert_eq!(
        Transformed::new(sphere.clone(), flat),
        Err(GeometryError::SingularTransform)
    );
    let mut projective = Mat4::IDENTITY;
    projective.x_axis.w = 0.5;
    assert_eq!(
        Transformed::new(sphere.clone(), projective),
        Err(GeometryError::NotAffine)
    );
    let mut nan = Mat4::IDENTITY;
    nan.w_axis.x = f32::NAN;
    assert_eq!(Transformed::new(sphere, nan), Err(GeometryError::NotFinite));
}

#[test]
fn closed_mesh_has_no_cracks_at_shared_vertices_and_edges() {
    // Rays from outside a closed sphere mesh of radius 2 aimed exactly at every
    // vertex and edge midpoint: each must stop at the near surface (t ≈ 1), not
    // slip through the shared point to the far side (t ≈ 5).
    let prims = raypack::scene::generate::test_scenes::uv_sphere_mesh(Vec3::ZERO, 2.0, 400);
    let accel = raypack::accel::BruteForce::new(&prims);
    let mut rays = 0;
    for p in &prims {
        let Primitive::Triangle(t) = p else { continue };
        let [a, b, c] = t.vertices();
        for target in [a, b, c, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)] {
            let origin = 3.0 * target.normalize();
            let r = Ray::unbounded(origin, (target - origin).normalize());
            let hit = raypack::accel::Accel::intersect(&accel, &r);
            assert!(hit.is_hit() && hit.t < 1.5, "crack at {target}: {hit:?}");
            let packet = RayPacket8::from_rays(&[r; 8]);
            let hits = raypack::accel::Accel::intersect_packet(&accel, &packet);
            assert_eq!(hits.hit(0).prim, hit.prim);
            rays += 1;
        }
    }
    assert!(rays > 2000, "{rays}");
}
