//! Scene generators: exact primitive counts per size, determinism per seed,
//! well-formed NFF (checked here entity by entity, and read back by raypack's
//! NFF reader), the SPD scenes' published eye-ray coverage, the committed
//! `scenes/` files, and the `raypack gen` command line.

use std::path::Path;
use std::process::Command;

use glam::Vec3;
use raypack::accel::{Accel, BruteForce};
use raypack::camera::Camera;
use raypack::geometry::{Primitive, PrimitiveKind};
use raypack::packet::RayPacket8;
use raypack::scene::generate::{GenerateError, Kind, Params};
use raypack::scene::{Scene, nff};
use raypack::simd::SimdFloat;

/// The camera of a `v` entity.
#[derive(Debug, Clone, Copy)]
struct View {
    from: Vec3,
    at: Vec3,
    up: Vec3,
    angle: f32,
    resolution: u32,
}

/// What an NFF file holds, as far as these tests look.
#[derive(Debug, Default)]
struct Nff {
    view: Option<View>,
    lights: usize,
    surfaces: usize,
    spheres: Vec<(Vec3, f32)>,
    polygons: Vec<Vec<Vec3>>,
    /// Cones and cylinders: base, base radius, apex, apex radius.
    cones: Vec<(Vec3, f32, Vec3, f32)>,
    /// Polygonal patches: vertices with their unit normals.
    patches: Vec<Vec<(Vec3, Vec3)>>,
    comments: Vec<String>,
}

/// Parse the NFF subset the generators write, checking its structure: known
/// keywords only, the right number of finite numbers for each, the camera and
/// lights before any primitive, a surface before the first primitive.
fn parse_nff(text: &str) -> Nff {
    let mut nff = Nff::default();
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let numbers = |n: usize, line: usize, fields: &[&str]| -> Vec<f32> {
        assert_eq!(
            fields.len(),
            n,
            "line {line}: expected {n} numbers, got {fields:?}"
        );
        fields
            .iter()
            .map(|f| {
                let v: f32 = f
                    .parse()
                    .unwrap_or_else(|_| panic!("line {line}: `{f}` is not a number"));
                assert!(v.is_finite(), "line {line}: `{f}` is not finite");
                v
            })
            .collect()
    };
    let vec3 = |v: &[f32]| Vec3::new(v[0], v[1], v[2]);
    while let Some((line, text)) = lines.next() {
        if let Some(comment) = text.strip_prefix('#') {
            nff.comments.push(comment.trim().to_string());
            continue;
        }
        let fields: Vec<&str> = text.split_whitespace().collect();
        let primitives = nff.spheres.len() + nff.polygons.len() + nff.cones.len() + nff.patches.len();
        match fields[0] {
            "v" => {
                assert!(
                    nff.view.is_none() && primitives == 0,
                    "line {line}: `v` must come first, once"
                );
                let mut entry = |key: &str| -> Vec<String> {
                    let (n, l) = lines
                        .next()
                        .unwrap_or_else(|| panic!("line {line}: `v` block cut short"));
                    let f: Vec<String> = l.split_whitespace().map(str::to_string).collect();
                    assert_eq!(f[0], key, "line {n}: expected `{key}`");
                    f[1..].to_vec()
                };
                let mut get = |key: &str, n: usize| {
                    let f = entry(key);
                    numbers(n, line, &f.iter().map(String::as_str).collect::<Vec<_>>())
                };
                let from = vec3(&get("from", 3));
                let at = vec3(&get("at", 3));
                let up = vec3(&get("up", 3));
                let angle = get("angle", 1)[0];
                let hither = get("hither", 1)[0];
                let resolution = get("resolution", 2);
                assert!(hither > 0.0 && resolution[0] == resolution[1]);
                nff.view = Some(View {
                    from,
                    at,
                    up,
                    angle,
                    resolution: resolution[0] as u32,
                });
            }
            "b" => {
                numbers(3, line, &fields[1..]);
            }
            "l" => {
                assert_eq!(primitives, 0, "line {line}: lights come before objects");
                numbers(3, line, &fields[1..]);
                nff.lights += 1;
            }
            "f" => {
                let f = numbers(8, line, &fields[1..]);
                // The index of refraction may be 0 where nothing transmits, as
                // the SPD writes it for rings, tree and teapot.
                assert!(
                    f[3] >= 0.0 && f[4] >= 0.0 && f[5] > 0.0 && f[7] >= 0.0 && (f[6] == 0.0 || f[7] > 0.0),
                    "line {line}: {f:?}"
                );
                nff.surfaces += 1;
            }
            "s" => {
                assert!(nff.surfaces > 0, "line {line}: a primitive before any surface");
                let s = numbers(4, line, &fields[1..]);
                assert!(s[3] > 0.0, "line {line}: radius");
                nff.spheres.push((vec3(&s), s[3]));
            }
            "p" => {
                assert!(nff.surfaces > 0, "line {line}: a primitive before any surface");
                let n: usize = fields[1].parse().unwrap();
                assert!(n >= 3 && fields.len() == 2, "line {line}");
                let vertices = (0..n)
                    .map(|_| {
                        let (l, t) = lines.next().expect("polygon cut short");
                        vec3(&numbers(3, l, &t.split_whitespace().collect::<Vec<_>>()))
                    })
                    .collect();
                nff.polygons.push(vertices);
            }
            "pp" => {
                assert!(nff.surfaces > 0, "line {line}: a primitive before any surface");
                let n: usize = fields[1].parse().unwrap();
                assert!(n >= 3 && fields.len() == 2, "line {line}");
                let corners = (0..n)
                    .map(|_| {
                        let (l, t) = lines.next().expect("patch cut short");
                        let v = numbers(6, l, &t.split_whitespace().collect::<Vec<_>>());
                        let normal = vec3(&v[3..]);
                        assert!((normal.length() - 1.0).abs() < 1e-4, "line {l}: normal {normal}");
                        (vec3(&v), normal)
                    })
                    .collect();
                nff.patches.push(corners);
            }
            "c" => {
                assert!(nff.surfaces > 0, "line {line}: a primitive before any surface");
                assert_eq!(fields.len(), 1, "line {line}");
                let mut end = || {
                    let (l, t) = lines.next().expect("cone cut short");
                    let v = numbers(4, l, &t.split_whitespace().collect::<Vec<_>>());
                    assert!(v[3] >= 0.0, "line {l}: radius");
                    (vec3(&v), v[3])
                };
                let ((base, base_radius), (apex, apex_radius)) = (end(), end());
                assert!(base != apex && base_radius + apex_radius > 0.0, "line {line}");
                nff.cones.push((base, base_radius, apex, apex_radius));
            }
            other => panic!("line {line}: unexpected entity `{other}`"),
        }
    }
    assert!(nff.view.is_some(), "no camera");
    nff
}

fn nff_of(kind: Kind, size: u32, seed: Option<u64>) -> String {
    Params::new(kind, Some(size), seed).unwrap().to_nff()
}

#[test]
fn primitive_counts_are_exact_for_every_size() {
    let sum9 = |n: u32| (0..=n).map(|i| 9usize.pow(i)).sum::<usize>();
    for size in 0..=4 {
        let balls = parse_nff(&nff_of(Kind::Sphereflake, size, None));
        assert_eq!(
            (balls.spheres.len(), balls.polygons.len()),
            (sum9(size), 1),
            "sphereflake {size}"
        );
        assert_eq!((balls.lights, balls.surfaces), (3, 2));

        let tetra = parse_nff(&nff_of(Kind::Tetra, size, None));
        assert_eq!(tetra.polygons.len(), 4usize.pow(size + 2), "tetra {size}");
        assert!(tetra.spheres.is_empty() && tetra.polygons.iter().all(|p| p.len() == 3));
        assert_eq!(tetra.lights, 1);

        let mount = parse_nff(&nff_of(Kind::FractalMountain, size, None));
        assert_eq!(mount.polygons.len(), 2 * 4usize.pow(size + 2), "mount {size}");
        assert_eq!(mount.spheres.len(), 4);
        assert!(mount.polygons.iter().all(|p| p.len() == 3));
        assert_eq!(mount.lights, 1);

        let terrain = parse_nff(&nff_of(Kind::Terrain, size, None));
        assert_eq!(terrain.polygons.len(), 2 * 4usize.pow(size), "terrain {size}");
    }
    for count in [1, 100, 1234] {
        let spheres = parse_nff(&nff_of(Kind::RandomSpheres, count, Some(5)));
        assert_eq!(
            (spheres.spheres.len(), spheres.polygons.len()),
            (count as usize, 0)
        );
        let triangles = parse_nff(&nff_of(Kind::RandomTriangles, count, Some(5)));
        assert_eq!(
            (triangles.spheres.len(), triangles.polygons.len()),
            (0, count as usize)
        );
    }
}

#[test]
fn the_classic_sizes_match_the_published_counts() {
    let total = |kind| {
        let nff = parse_nff(&Params::new(kind, None, None).unwrap().to_nff());
        nff.spheres.len() + nff.polygons.len()
    };
    assert_eq!(total(Kind::Sphereflake), 7382);
    assert_eq!(total(Kind::FractalMountain), 8196);
    assert_eq!(total(Kind::Tetra), 4096);
}

/// Rings, tree and teapot at their defaults hold the SPD 3.4 README's
/// primitives, of the kinds it lists, as raypack's reader sees them.
#[test]
fn rings_tree_and_teapot_have_the_published_primitives() {
    use PrimitiveKind::{Cone, Polygon, Sphere, Triangle};
    let expected = [
        (
            Kind::Rings,
            8401,
            [(Cone, 4200), (Sphere, 4200), (Polygon, 1), (Triangle, 0)],
            3,
        ),
        (
            Kind::Tree,
            8191,
            [(Cone, 4095), (Sphere, 4095), (Polygon, 1), (Triangle, 0)],
            7,
        ),
        (
            Kind::Teapot,
            9264,
            [(Cone, 0), (Sphere, 0), (Polygon, 144), (Triangle, 9120)],
            2,
        ),
    ];
    for (kind, total, kinds, lights) in expected {
        let params = Params::new(kind, None, None).unwrap();
        let scene = read(&params.to_nff());
        assert_eq!(scene.primitives.len(), total, "{kind:?}");
        assert_eq!(params.primitive_count(), total as u64, "{kind:?}");
        for (k, n) in kinds {
            assert_eq!(count_of(&scene, k), n, "{kind:?}: {k:?}");
        }
        assert_eq!(scene.lights.len(), lights, "{kind:?}");
        let camera = scene.camera.expect("a camera");
        assert_eq!((camera.width, camera.height), (512, 512));
        assert!(camera.camera().is_ok(), "{kind:?}");
    }
    // Every teapot triangle is smooth shaded.
    let teapot = read(&Params::new(Kind::Teapot, None, None).unwrap().to_nff());
    assert_eq!(teapot.vertex_normals.len(), 9120);
}

#[test]
fn rings_tree_and_teapot_small_sizes_and_bad_sizes() {
    for size in 1..=4 {
        for (kind, count) in [
            (Kind::Rings, 10 * size * (size + 1) * (2 * size + 1) + 1),
            (Kind::Tree, 2 * ((1 << (size + 1)) - 1) + 1),
            (Kind::Teapot, 64 * size * size - 8 * size + size * size),
        ] {
            let text = nff_of(kind, size as u32, None);
            let nff = parse_nff(&text);
            let written = nff.spheres.len() + nff.polygons.len() + nff.cones.len() + nff.patches.len();
            assert_eq!(written, count, "{kind:?} {size}");
            assert_eq!(read(&text).primitives.len(), count, "{kind:?} {size}");
        }
    }
    // The smallest tree is the trunk: one cone, its sphere, the field.
    let trunk = parse_nff(&nff_of(Kind::Tree, 0, None));
    assert_eq!(
        (trunk.cones.len(), trunk.spheres.len(), trunk.polygons.len()),
        (1, 1, 1)
    );
    let (base, base_radius, apex, apex_radius) = trunk.cones[0];
    assert_eq!((base, apex), (Vec3::ZERO, Vec3::Z));
    assert!((base_radius - 0.15).abs() < 1e-6 && (apex_radius - 0.1005).abs() < 1e-6);
    assert_eq!(trunk.spheres[0], (Vec3::Z, apex_radius));
    // One rings object: 6 rings of 5 cylinders, all of the published radius.
    let rings = parse_nff(&nff_of(Kind::Rings, 1, None));
    assert_eq!(rings.surfaces, 1 + 6);
    assert!(rings.cones.iter().all(|c| c.1 == 0.07412 && c.3 == 0.07412));
    // The teapot's triangles stay on its patches' hull, above the board.
    let teapot = parse_nff(&nff_of(Kind::Teapot, 3, None));
    for corner in teapot.patches.iter().flatten() {
        assert!(
            corner.0.z >= 0.0 && corner.0.z <= 3.15 + 1e-5 && corner.0.x.abs() <= 3.525,
            "{corner:?}"
        );
    }
    for (kind, bad) in [
        (Kind::Rings, 0),
        (Kind::Rings, 51),
        (Kind::Tree, 21),
        (Kind::Teapot, 0),
        (Kind::Teapot, 201),
    ] {
        assert!(
            matches!(
                Params::new(kind, Some(bad), None),
                Err(GenerateError::SizeOutOfRange { .. })
            ),
            "{kind:?} {bad}"
        );
        assert_eq!(
            Params::new(kind, None, Some(1)),
            Err(GenerateError::NotRandom(kind.name()))
        );
    }
}

/// Lattice, shells and jacks (later SPD additions, no published ray counts)
/// hold the primitives of their SPD descriptions, at the SPD's default size
/// factors (12, 5, 1) and at small ones, as raypack's reader sees them.
#[test]
fn lattice_shells_and_jacks_have_their_described_primitives() {
    use PrimitiveKind::{Cone, Sphere};
    for (kind, total, cones, lights) in [
        (Kind::Lattice, 8281, 6084, 6),
        (Kind::Shells, 5761, 0, 1),
        (Kind::Jacks, 9, 3, 1),
    ] {
        let params = Params::new(kind, None, None).unwrap();
        let scene = read(&params.to_nff());
        assert_eq!(scene.primitives.len(), total, "{kind:?}");
        assert_eq!(params.primitive_count(), total as u64, "{kind:?}");
        assert_eq!(count_of(&scene, Cone), cones, "{kind:?}");
        assert_eq!(count_of(&scene, Sphere), total - cones, "{kind:?}");
        assert_eq!(scene.lights.len(), lights, "{kind:?}");
        assert!(scene.camera.expect("a camera").camera().is_ok(), "{kind:?}");
    }
    for size in 1..=3u64 {
        for (kind, count) in [
            (Kind::Lattice, (size + 1).pow(3) + 3 * size * (size + 1).pow(2)),
            (Kind::Shells, 180 * (1 << size) + 1),
            (Kind::Jacks, 9 * ((1 << (3 * size)) - 1) / 7),
        ] {
            let text = nff_of(kind, size as u32, None);
            let nff = parse_nff(&text);
            assert_eq!(
                (nff.spheres.len() + nff.cones.len()) as u64,
                count,
                "{kind:?} {size}"
            );
            assert_eq!(read(&text).primitives.len() as u64, count, "{kind:?} {size}");
        }
    }
    // The lattice's rods stop inside the spheres they join, and never reach the centre.
    let lattice = parse_nff(&nff_of(Kind::Lattice, 2, None));
    for (base, _, apex, radius) in &lattice.cones {
        assert!((radius - 1.0 / 32.0).abs() < 1e-6);
        let length = (*apex - *base).length();
        assert!(length > 0.5 - 2.0 * 0.125 && length < 0.5, "{length}");
    }
    // Each jack's six spheres sit at its arms' ends: all 9 primitives of size 1
    // lie within the 0.75 arm plus the 0.15 sphere of the origin.
    let jacks = parse_nff(&nff_of(Kind::Jacks, 1, None));
    assert!(
        jacks
            .spheres
            .iter()
            .all(|(c, r)| (c.length() - 0.75).abs() < 1e-5 && *r == 0.15)
    );
    for (kind, bad) in [(Kind::Lattice, 0), (Kind::Shells, 13), (Kind::Jacks, 8)] {
        assert!(
            matches!(
                Params::new(kind, Some(bad), None),
                Err(GenerateError::SizeOutOfRange { .. })
            ),
            "{kind:?} {bad}"
        );
    }
}

#[test]
fn headers_say_what_and_how() {
    // An instanced kind has no NFF (`gen` writes it as glTF, tests/cli/instances.rs).
    for kind in Kind::ALL.into_iter().filter(|k| !k.is_instanced()) {
        let params = Params::new(kind, Some(1), None).unwrap();
        let nff = parse_nff(&params.to_nff());
        assert_eq!(nff.comments[0], params.title());
        assert_eq!(nff.comments[1], format!("Made by: {}", params.command()));
        // The command reproduces the text.
        let again = Params::new(kind, Some(params.size), params.seed).unwrap();
        assert_eq!(again.to_nff(), params.to_nff());
    }
}

#[test]
fn output_is_determined_by_the_seed() {
    for kind in [
        Kind::RandomSpheres,
        Kind::RandomTriangles,
        Kind::Terrain,
        Kind::FractalMountain,
    ] {
        let size = if kind == Kind::Terrain || kind == Kind::FractalMountain {
            2
        } else {
            300
        };
        let a = nff_of(kind, size, Some(9));
        assert_eq!(a, nff_of(kind, size, Some(9)), "{kind:?}");
        assert_ne!(a, nff_of(kind, size, Some(10)), "{kind:?}: the seed must matter");
    }
    for kind in [Kind::Sphereflake, Kind::Tetra] {
        assert_eq!(nff_of(kind, 2, None), nff_of(kind, 2, None));
    }
}

#[test]
fn random_content_stays_in_its_cube() {
    let spheres = parse_nff(&nff_of(Kind::RandomSpheres, 2000, Some(3)));
    assert!(spheres.spheres.iter().all(|(c, _)| c.abs().max_element() <= 1.0));
    let triangles = parse_nff(&nff_of(Kind::RandomTriangles, 2000, Some(3)));
    let s = 0.5 * (8.0f32 / 2000.0).cbrt();
    for t in &triangles.polygons {
        // Corners lie on a sphere of radius s about a centre inside the cube.
        assert!(t.iter().all(|p| p.abs().max_element() <= 1.0 + s + 1e-4));
        assert!(
            (t[1] - t[0]).cross(t[2] - t[0]).length() >= 0.019 * s * s,
            "thin triangle {t:?}"
        );
    }
}

#[test]
fn sphereflake_geometry() {
    let nff = parse_nff(&nff_of(Kind::Sphereflake, 3, None));
    // All spheres fit in the radius-1 ball the SPD says encloses the object.
    assert!(nff.spheres.iter().all(|(c, r)| c.length() + r <= 1.0 + 1e-5));
    // The root, then its first child as the published file has it.
    assert_eq!(nff.spheres[0], (Vec3::ZERO, 0.5));
    let (c, r) = nff.spheres[1];
    assert!((c - Vec3::new(0.272166, 0.272166, 0.544331)).length() < 1e-6 && (r - 0.166667).abs() < 1e-6);
    // Every child touches its parent: some sphere of thrice its radius lies
    // exactly one parent radius plus one child radius away.
    for &(c, r) in &nff.spheres[1..] {
        let touches = nff
            .spheres
            .iter()
            .any(|&(pc, pr)| (pr - 3.0 * r).abs() < 1e-5 && ((pc - c).length() - (pr + r)).abs() < 1e-5);
        assert!(touches, "sphere at {c} has no parent");
    }
}

#[test]
fn mountain_covers_its_square_without_cracks() {
    let nff = parse_nff(&nff_of(Kind::FractalMountain, 1, None));
    let mut area = 0.0;
    for t in &nff.polygons {
        // Counter-clockwise seen from above, so the z of the normal is positive.
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        assert!(n.z > 0.0);
        area += 0.5 * n.z;
    }
    assert!(
        (area - 4.0).abs() < 1e-4,
        "the xy projections tile [-1, 1]²: {area}"
    );
    // A shared grid point has one height whichever triangle states it.
    let mut heights = std::collections::HashMap::new();
    for p in nff.polygons.iter().flatten() {
        let key = ((p.x * 1000.0).round() as i32, (p.y * 1000.0).round() as i32);
        assert_eq!(*heights.entry(key).or_insert(p.z), p.z, "crack at {p}");
    }
}

/// An NFF text read by raypack's own reader.
fn read(text: &str) -> Scene {
    nff::parse(Path::new("generated.nff"), text.as_bytes()).unwrap_or_else(|e| panic!("{e}"))
}

/// How many primitives of `kind` the scene holds.
fn count_of(scene: &Scene, kind: PrimitiveKind) -> usize {
    scene.primitives.iter().filter(|p| p.kind() == kind).count()
}

/// Fraction of the SPD's eye rays (through pixel corners, 513 × 513 at 512²)
/// that hit something, from every `stride`-th row and column.
fn eye_hit_fraction(text: &str, stride: usize) -> f64 {
    let nff = parse_nff(text);
    let view = nff.view.unwrap();
    let res = view.resolution;
    // NFF's angle spans the outer pixel rows' centres, i.e. the corner rays:
    // corner coordinates 0 and `res` of a `res`-wide image span exactly fov.
    let camera = Camera::new(view.from, view.at, view.up, view.angle, view.angle, res, res).unwrap();
    let prims: Vec<Primitive> = read(text).primitives;
    let accel = BruteForce::new(&prims);
    let rays: Vec<_> = (0..=res as usize)
        .step_by(stride)
        .flat_map(|j| (0..=res as usize).step_by(stride).map(move |i| (i, j)))
        .map(|(i, j)| camera.ray(i as f32, j as f32))
        .collect();
    let hits: u32 = rays
        .chunks(8)
        .map(|chunk| {
            let packet = RayPacket8::from_rays(chunk);
            (packet.active & accel.intersect_packet(&packet).hit_mask())
                .bitmask()
                .count_ones()
        })
        .sum();
    f64::from(hits) / rays.len() as f64
}

/// The SPD's published eye hit rays (of 513² = 263,169) must come out within a
/// few percent; the SPD allows 10% between ray tracers.
#[test]
fn spd_scenes_cover_the_published_share_of_the_image() {
    let published = [
        (Kind::Sphereflake, 263_169.0),
        (Kind::Tetra, 49_788.0),
        (Kind::FractalMountain, 173_125.0),
        (Kind::Rings, 263_169.0),
        (Kind::Tree, 169_836.0),
        (Kind::Teapot, 161_120.0),
    ];
    for (kind, hits) in published {
        let expected = hits / 263_169.0;
        let got = eye_hit_fraction(&Params::new(kind, None, None).unwrap().to_nff(), 4);
        println!(
            "{kind:?}: eye rays hitting {:.2}% (published {:.2}%)",
            100.0 * got,
            100.0 * expected
        );
        assert!(
            (got - expected).abs() <= 0.03 * expected,
            "{kind:?}: {got} vs {expected}"
        );
    }
}

#[test]
fn committed_scenes_are_the_generators_output() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let files = [
        ("spd_balls.nff", Kind::Sphereflake, 4),
        ("spd_tetra.nff", Kind::Tetra, 4),
        ("spd_mount.nff", Kind::FractalMountain, 4),
        ("spd_balls_small.nff", Kind::Sphereflake, 2),
        ("spd_tetra_small.nff", Kind::Tetra, 1),
        ("spd_mount_small.nff", Kind::FractalMountain, 1),
        ("spd_gears_small.nff", Kind::Gears, 1),
        ("spd_rings_small.nff", Kind::Rings, 1),
        ("spd_tree_small.nff", Kind::Tree, 3),
        ("spd_teapot_small.nff", Kind::Teapot, 2),
    ];
    for (name, kind, size) in files {
        let text = std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let params = Params::new(kind, Some(size), None).unwrap();
        assert!(
            text == params.to_nff(),
            "{name} is stale: regenerate it with `{} -o scenes/{name}`",
            params.command()
        );
    }
}

fn raypack(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_raypack"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn cli_writes_stdout_or_a_file_and_refuses_bad_input_with_exit_2() {
    let out = raypack(&["gen", "tetra", "--size", "1"]);
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8(out.stdout).unwrap(),
        nff_of(Kind::Tetra, 1, None)
    );

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("mount.nff");
    let out = raypack(&[
        "gen",
        "mount",
        "--size",
        "1",
        "--seed",
        "4",
        "-o",
        file.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(
        std::fs::read_to_string(&file).unwrap(),
        nff_of(Kind::FractalMountain, 1, Some(4))
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary file left behind"
    );

    for (args, message) in [
        (
            vec!["gen", "sphereflake", "--size", "9"],
            "--size 9 is out of range",
        ),
        (vec!["gen", "tetra", "--seed", "3"], "tetra is not random"),
        (
            vec!["gen", "random-spheres", "--size", "0"],
            "--size 0 is out of range",
        ),
        (
            vec!["gen", "fractal-mountain", "--seed", "99999999"],
            "--seed 99999999 is out of range",
        ),
        (vec!["gen", "rings", "--size", "0"], "--size 0 is out of range"),
        (vec!["gen", "teapot", "--seed", "1"], "teapot is not random"),
    ] {
        let out = raypack(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(String::from_utf8_lossy(&out.stderr).contains(message), "{args:?}");
    }
    let missing = dir.path().join("no/such/dir/x.nff");
    let out = raypack(&["gen", "tetra", "-o", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot write"));
    assert!(!missing.exists());
}

/// One random-sphere law: `raypack gen random-spheres` writes the spheres of
/// the scene argument `gen:spheres` (to NFF's six digits), and
/// `gen:random-spheres` reads back the same.
#[test]
fn gen_random_spheres_and_gen_spheres_are_the_same_scene() {
    use raypack::scene::generate::test_scenes::from_spec;
    let spheres = |prims: &[Primitive]| -> Vec<(Vec3, f32)> {
        prims
            .iter()
            .map(|p| match p {
                Primitive::Sphere(s) => (s.center, s.radius),
                other => panic!("not a sphere: {other:?}"),
            })
            .collect()
    };
    let out = raypack(&["gen", "random-spheres", "--size", "1000", "--seed", "7"]);
    assert!(out.status.success());
    let written = raypack::scene::nff::parse(Path::new("random-spheres.nff"), &out.stdout).unwrap();
    let in_code = from_spec("gen:spheres:1000:7").unwrap().unwrap();
    let by_kind = from_spec("gen:random-spheres:1000:7").unwrap().unwrap();
    let expected = spheres(&in_code.primitives);
    assert_eq!(expected.len(), 1000);
    for scene in [&written, &by_kind] {
        let got = spheres(&scene.primitives);
        assert_eq!(got.len(), expected.len());
        for ((c, r), (ce, re)) in got.iter().zip(&expected) {
            assert!(
                (*c - *ce).abs().max_element() <= 1e-5 && (r - re).abs() <= 1e-6,
                "{c} {r} vs {ce} {re}"
            );
        }
    }
    // Another seed is another scene.
    let other = from_spec("gen:spheres:1000:8").unwrap().unwrap();
    assert_ne!(spheres(&other.primitives)[0], expected[0]);
}
