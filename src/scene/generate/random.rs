//! Generated primitives for tests, benchmarks and the engine comparisons
//! (`gen:` scenes, [`test_scenes`](crate::scene::generate::test_scenes)): random
//! primitives of every kind in the cube `[-1, 1]³`, and a finely tessellated
//! bumpy sphere standing in for a scanned mesh. Sizes shrink as `n^(-1/3)` so
//! the density of the scene, not its overlap, stays the same as `n` grows.
//! All randomness comes from a seeded [`Rng`].

use glam::{Mat4, Quat, Vec3};

use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::geometry::plane::Plane;
use crate::geometry::{Polygon, Primitive, Sphere, Transformed, Triangle};
use crate::rng::Rng;
use crate::scene::CameraSpec;

/// The edge length of the cube a primitive of an `n`-primitive scene roughly fills.
fn cell(n: usize) -> f32 {
    2.0 / (n.max(1) as f32).cbrt()
}

/// `n` spheres with centres uniform in `[-1, 1]³` and radii uniform in
/// `[0.1, 0.5]` of a cell: the one random-sphere law, used by `gen:spheres`
/// and by `raypack gen random-spheres` alike.
pub fn spheres(n: usize, seed: u64) -> Vec<Sphere> {
    let mut rng = Rng::new(seed);
    let size = cell(n);
    (0..n)
        .map(|_| {
            let c = rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0));
            Sphere::new(c, rng.range(0.1, 0.5) * size)
        })
        .collect()
}

/// [`spheres`] as primitives.
pub fn random_spheres(n: usize, seed: u64) -> Vec<Primitive> {
    spheres(n, seed).into_iter().map(Primitive::Sphere).collect()
}

/// A random triangle of about `size` around a random point of `[-1, 1]³`.
fn random_triangle(rng: &mut Rng, size: f32) -> Triangle {
    let c = rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0));
    let mut v = || c + 0.6 * size * rng.unit_vector();
    Triangle::new(v(), v(), v())
}

/// `n` randomly placed and oriented triangles.
pub fn random_triangles(n: usize, seed: u64) -> Vec<Primitive> {
    let mut rng = Rng::new(seed);
    let size = cell(n);
    (0..n)
        .map(|_| Primitive::Triangle(random_triangle(&mut rng, size)))
        .collect()
}

/// A random planar polygon of about `size` around a random point of
/// `[-1, 1]³`: a regular polygon or a concave star of 3 to 12 points, in a
/// random plane.
fn random_polygon(rng: &mut Rng, size: f32) -> Polygon {
    let c = rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0));
    let rotation = Quat::from_axis_angle(rng.unit_vector(), rng.range(0.0, std::f32::consts::TAU));
    let points = 3 + rng.below(10) as usize;
    let star = rng.below(2) == 0;
    let vertices: Vec<Vec3> = (0..if star { 2 * points } else { points })
        .map(|i| {
            let (r, a) = if star {
                (
                    if i % 2 == 0 { 0.5 } else { 0.2 },
                    i as f32 * std::f32::consts::PI / points as f32,
                )
            } else {
                (0.5, i as f32 * std::f32::consts::TAU / points as f32)
            };
            c + rotation * (size * r * Vec3::new(a.cos(), a.sin(), 0.0))
        })
        .collect();
    Polygon::new(&vertices).expect("a regular polygon or star is valid")
}

/// `n` random polygons, convex and concave.
pub fn random_polygons(n: usize, seed: u64) -> Vec<Primitive> {
    let mut rng = Rng::new(seed);
    let size = cell(n);
    (0..n)
        .map(|_| Primitive::Polygon(random_polygon(&mut rng, size)))
        .collect()
}

/// `n` transformed primitives: unit spheres, triangles and polygons placed by
/// random scale (anisotropic), rotation and translation matrices; one in five
/// is nested in a second transform (a sheared object inside an instance).
pub fn random_transformed(n: usize, seed: u64) -> Vec<Primitive> {
    let mut rng = Rng::new(seed);
    let size = cell(n);
    (0..n)
        .map(|i| {
            let mut object = match i % 3 {
                0 => Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)),
                1 => Primitive::Triangle(random_triangle(&mut Rng::new(seed ^ i as u64), 1.0)),
                _ => Primitive::Polygon(random_polygon(&mut Rng::new(seed ^ i as u64), 1.0)),
            };
            if i % 5 == 0 {
                let inner = Mat4::from_scale(Vec3::new(1.0, 0.5, 1.0)) * Mat4::from_rotation_z(0.7);
                object = Primitive::Transformed(Box::new(
                    Transformed::new(object, inner).expect("invertible transform"),
                ));
            }
            // Centre the object on the origin first, so the matrix's translation places it.
            let centre = object.bounds().map_or(Vec3::ZERO, |b| b.center());
            let scale = Vec3::new(rng.range(0.1, 0.5), rng.range(0.1, 0.5), rng.range(0.1, 0.5)) * size;
            let axis = rng.unit_vector();
            let rotation = Quat::from_axis_angle(axis, rng.range(0.0, std::f32::consts::TAU));
            let offset = rng.point_in(Vec3::splat(-1.0), Vec3::splat(1.0));
            let m = Mat4::from_scale_rotation_translation(scale, rotation, offset)
                * Mat4::from_translation(-centre);
            Primitive::Transformed(Box::new(
                Transformed::new(object, m).expect("invertible transform"),
            ))
        })
        .collect()
}

/// Three planes around the cube, one of each form: a floor, a tilted back wall, a side wall.
pub fn bounding_planes() -> Vec<Primitive> {
    vec![
        Primitive::Plane(Plane::implicit(0.0, 1.0, 0.0, 1.5).expect("valid plane")),
        Primitive::Plane(
            Plane::point_normal(Vec3::new(0.0, 0.0, -2.0), Vec3::new(0.1, 0.2, 1.0)).expect("valid plane"),
        ),
        Primitive::Plane(
            Plane::parametric(
                Vec3::new(2.5, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.1),
                Vec3::new(0.2, 0.0, 1.0),
            )
            .expect("valid plane"),
        ),
    ]
}

/// About `n` primitives of every kind, interleaved, plus [`bounding_planes`].
pub fn random_mixed(n: usize, seed: u64) -> Vec<Primitive> {
    let quarter = n.div_ceil(4);
    let kinds = [
        random_spheres(quarter, seed),
        random_triangles(quarter, seed + 1),
        random_polygons(quarter, seed + 2),
        random_transformed(quarter, seed + 3),
    ];
    let mut prims = bounding_planes();
    for i in 0..quarter {
        prims.extend(kinds.iter().map(|k| k[i].clone()));
    }
    prims
}

/// A closed triangle mesh of about `n` triangles: a UV sphere of radius about 1
/// whose radius is modulated by a few random waves, like a scanned object's surface.
pub fn bumpy_sphere(n: usize, seed: u64) -> Vec<Primitive> {
    let mut rng = Rng::new(seed);
    let waves: Vec<(Vec3, f32, f32)> = (0..8)
        .map(|_| {
            (
                rng.unit_vector(),
                rng.range(2.0, 12.0),
                rng.range(0.0, std::f32::consts::TAU),
            )
        })
        .collect();
    let radius = |dir: Vec3| {
        1.0 + waves
            .iter()
            .map(|&(axis, freq, phase)| 0.015 * (freq * dir.dot(axis) + phase).sin())
            .sum::<f32>()
    };
    // rings × segments quads, the two polar rings as single triangles: 2·s·(r − 1) triangles.
    let rings = ((n as f32 / 4.0).sqrt().round() as usize).max(2);
    let segments = 2 * rings;
    let vertex = |i: usize, j: usize| {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        let phi = std::f32::consts::TAU * (j % segments) as f32 / segments as f32;
        let dir = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
        radius(dir) * dir
    };
    let mut prims = Vec::with_capacity(2 * segments * (rings - 1));
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (
                vertex(i, j),
                vertex(i + 1, j),
                vertex(i + 1, j + 1),
                vertex(i, j + 1),
            );
            if i != 0 {
                prims.push(Primitive::Triangle(Triangle::new(a, c, d)));
            }
            if i != rings - 1 {
                prims.push(Primitive::Triangle(Triangle::new(a, b, c)));
            }
        }
    }
    prims
}

/// The camera of [`CameraSpec::framing`] at `width × height`.
pub fn framing_camera(bounds: Aabb, width: u32, height: u32) -> Camera {
    CameraSpec::framing(bounds, width, height)
        .camera()
        .expect("a framing camera is valid")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generators_make_the_requested_counts() {
        assert_eq!(random_spheres(10, 1).len(), 10);
        assert_eq!(random_triangles(10, 1).len(), 10);
        assert_eq!(random_polygons(10, 1).len(), 10);
        assert_eq!(random_transformed(10, 1).len(), 10);
        assert_eq!(random_mixed(40, 1).len(), 43);
        let mesh = bumpy_sphere(1000, 1);
        assert!((900..1100).contains(&mesh.len()), "{}", mesh.len());
        assert!(
            mesh.iter().all(|p| p.bounds().is_some()),
            "no degenerate triangles"
        );
    }

    #[test]
    fn framing_camera_sees_small_and_large_scenes() {
        use crate::accel::{Accel, BruteForce};
        for scale in [0.01f32, 1.0, 100.0] {
            let prims: Vec<Primitive> = random_spheres(50, 3)
                .iter()
                .map(|p| match p {
                    Primitive::Sphere(s) => {
                        Primitive::Sphere(Sphere::new(scale * s.center, scale * s.radius))
                    }
                    _ => unreachable!("only spheres"),
                })
                .collect();
            let bounds = prims
                .iter()
                .filter_map(Primitive::bounds)
                .fold(Aabb::EMPTY, Aabb::union);
            let camera = framing_camera(bounds, 32, 32);
            let brute = BruteForce::new(&prims);
            let hits = (0..32 * 32)
                .filter(|k| brute.intersect(&camera.pixel_ray(k % 32, k / 32)).is_hit())
                .count();
            assert!(hits > 32 * 32 / 10, "scale {scale}: {hits} hits");
        }
    }
}
