//! The NFF reader: every entity on a good file, and malformed files, each of
//! which must fail with `file:line: expected …, found …` naming the right line.

use crate::support::scratch::Scratch;
use glam::Vec3;
use raypack::accel::{Accel, BruteForce};
use raypack::geometry::{Primitive, PrimitiveKind};
use raypack::ray::Ray;
use raypack::scene::{self, Material, SceneError, nff};
use std::path::Path;

/// A file with every NFF entity, comments in odd places, tabs and CRLF endings.
const EVERY_ENTITY: &str = "# every entity\r
v\r
from 0 0 10\r
at 0 0 0\r
up 0 1 0\r
angle 45\r
hither 1\r
resolution 64 48\r
b 0.1 0.2 0.3\r
l 1 2 3\r
l 4 5 6 0.5 0.25 1 # a coloured light\r
s 0 0 -5 1\r
f 1 0 0 0.7 0.3 20 0 1\r
s 3 0 -5 -2\r
p 3\r
0 0 0\t1 0 0\r
0 1 0\r
f 0 0 1 0.5 0.5 10 0.8 1.5\r
pp 3\r
0 0 1 0 0 2\r
1 0 1 0 0 1\r
0 1 1 0 0 1#normals need not be unit\r
pp 4\r
0 0 2 0 0 1  1 0 2 0 0 1  1 1 2 0 0 1  0 1 2 0 0 1\r
c 0 0 0 1 0 2 0 0.5\r
";

fn parse(text: &str) -> Result<scene::Scene, SceneError> {
    nff::parse(Path::new("test.nff"), text.as_bytes())
}

#[test]
fn every_entity_is_read() {
    let s = parse(EVERY_ENTITY).unwrap();
    let kinds = crate::kinds(&s);
    use PrimitiveKind::*;
    // `p 3` is the triangle it is; `pp 4` a flat polygon.
    assert_eq!(kinds, [Sphere, Sphere, Triangle, Triangle, Polygon, Cone]);
    // Materials: the default one for the first sphere, then one per `f`.
    assert_eq!(s.material_of, [0, 1, 1, 2, 2, 2]);
    assert_eq!(s.materials[0], Material::default());
    assert_eq!(s.materials[1].color, Vec3::X);
    assert_eq!(
        (s.materials[1].kd, s.materials[1].ks, s.materials[1].shine),
        (0.7, 0.3, 20.0)
    );
    assert_eq!((s.materials[2].transmittance, s.materials[2].ior), (0.8, 1.5));
    // Lights: white by default, else their colour.
    assert_eq!(s.lights.len(), 2);
    assert_eq!(s.lights[0].color, Vec3::ONE);
    assert_eq!(s.lights[1].position, Vec3::new(4.0, 5.0, 6.0));
    assert_eq!(s.lights[1].color, Vec3::new(0.5, 0.25, 1.0));
    assert_eq!(s.background, Vec3::new(0.1, 0.2, 0.3));
    // The negative radius: inside-only, radius kept positive.
    let Primitive::Sphere(inside) = &s.primitives[1] else {
        panic!()
    };
    assert!(inside.inside_only && inside.radius == 2.0);
    let Primitive::Sphere(outside) = &s.primitives[0] else {
        panic!()
    };
    assert!(!outside.inside_only);
    // The 3-vertex patch keeps its normals (normalised), by primitive index.
    assert_eq!(s.vertex_normals.len(), 1);
    assert_eq!(s.vertex_normals[&3], [Vec3::Z; 3]);
    let Primitive::Cone(cone) = &s.primitives[5] else {
        panic!()
    };
    assert_eq!(
        (cone.base_radius(), cone.apex(), cone.apex_radius()),
        (1.0, Vec3::new(0.0, 2.0, 0.0), 0.5)
    );
    let cam = s.camera.unwrap();
    assert_eq!(
        (cam.eye, cam.center, cam.up),
        (Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y)
    );
    assert_eq!((cam.width, cam.height), (64, 48));
    assert_eq!(s.source, "test.nff");
}

#[test]
fn nff_angle_spans_pixel_centres() {
    let s = parse(EVERY_ENTITY).unwrap();
    let spec = s.camera.unwrap();
    let cam = spec.camera().unwrap();
    // The centre of the top pixel row and of the leftmost pixel column lie
    // angle/2 = 22.5° off the view axis (image coordinates: centre at (32, 24)).
    let axis = -cam.w;
    for (x, y) in [(32.0, 0.5), (32.0, 47.5), (0.5, 24.0), (63.5, 24.0)] {
        let off = cam.ray(x, y).dir.angle_between(axis).to_degrees();
        assert!((off - 22.5).abs() < 1e-3, "({x}, {y}): {off}°");
    }
    // So the edge-to-edge fields of view are a little wider, and differ with the row count.
    let expect = |n: f32| 2.0 * ((22.5f32).to_radians().tan() * n / (n - 1.0)).atan().to_degrees();
    assert!((spec.fovx - expect(64.0)).abs() < 1e-4 && (spec.fovy - expect(48.0)).abs() < 1e-4);
    assert!(spec.fovy > spec.fovx && spec.fovx > 45.0);
}

#[test]
fn concave_polygons_stay_polygons() {
    // An L shape: the notch at (1.5, 1.5) is outside, the arms are inside.
    let s = parse("p 6\n0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n").unwrap();
    assert_eq!(s.primitives[0].kind(), PrimitiveKind::Polygon);
    let accel = BruteForce::new(&s.primitives);
    let down = |x: f32, y: f32| accel.intersect(&Ray::unbounded(Vec3::new(x, y, 5.0), -Vec3::Z));
    assert!(down(0.5, 1.5).is_hit() && down(1.5, 0.5).is_hit());
    assert!(!down(1.5, 1.5).is_hit());
    assert_eq!(down(0.5, 0.5).t, 5.0);
}

#[test]
fn comments_and_white_space_anywhere() {
    let a = parse("s 1 2 3 4\n").unwrap();
    let b = parse("# head\n\n  s\t1 # x\n 2\r\n# between\n3 4# tail\n#").unwrap();
    assert_eq!(a.primitives, b.primitives);
}

#[test]
fn loading_twice_gives_identical_geometry() {
    let a = parse(EVERY_ENTITY).unwrap();
    let b = parse(EVERY_ENTITY).unwrap();
    assert_eq!(a.primitives, b.primitives);
    assert_eq!(a.material_of, b.material_of);
    assert_eq!(a.materials, b.materials);
    assert_eq!(a.vertex_normals, b.vertex_normals);
    assert_eq!((a.lights, a.camera), (b.lights, b.camera));
}

/// Parse `text` expecting an error on `line` whose message contains `needle`.
#[track_caller]
fn fails(text: impl AsRef<[u8]>, line: usize, needle: &str) {
    let e = nff::parse(Path::new("bad.nff"), text.as_ref()).expect_err("must not load");
    let shown = e.to_string();
    assert_eq!(e.line, Some(line), "{shown}");
    assert!(
        shown.starts_with(&format!("bad.nff:{line}: expected ")),
        "{shown}"
    );
    assert!(shown.contains(needle), "`{shown}` lacks `{needle}`");
}

#[test]
fn truncated_files() {
    fails("s 0 0 1", 1, "the sphere radius, found end of file");
    fails(
        "s 0 0 -5 1\np 4\n0 0 0\n1 0 0\n1 1 0\n",
        5,
        "polygon vertex 4 of 4, found end of file",
    );
    fails("c 0 0 0 1\n0 1 0", 2, "the cone's apex radius, found end of file");
    fails(
        "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0",
        4,
        "patch normal 3 of 3, found end of file",
    );
    fails("v\nfrom 0 0 1\nat 0 0 0\n", 3, "`up`");
    fails(
        "s 0 0 0 1\nl 1 2 3 0.5",
        2,
        "the green of the light colour, found end of file",
    );
}

#[test]
fn wrong_vertex_counts() {
    // One vertex too many: the extra number is where a keyword should be.
    fails(
        "p 3\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n",
        5,
        "an NFF keyword (v, b, l, f, s, p, pp, c), found `1`",
    );
    // One too few: the next keyword is where a number should be.
    fails(
        "p 4\n0 0 0\n1 0 0\n0 1 0\ns 0 0 0 1\n",
        5,
        "x of polygon vertex 4 of 4 (a number), found `s`",
    );
    fails(
        "p 3.5\n0 0 0\n1 0 0\n0 1 0\n",
        1,
        "the polygon's vertex count (an integer ≥ 3), found `3.5`",
    );
    fails("p -3\n", 1, "found `-3`");
}

#[test]
fn polygons_with_fewer_than_three_vertices() {
    fails(
        "p 2\n0 0 0\n1 0 0\n",
        1,
        "the polygon's vertex count (an integer ≥ 3), found `2`",
    );
    fails(
        "s 0 0 0 1\n\npp 0\n",
        3,
        "the patch's vertex count (an integer ≥ 3), found `0`",
    );
}

#[test]
fn collinear_first_vertices() {
    fails(
        "s 0 0 0 1\np 4\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n",
        2,
        "first three vertices span a plane",
    );
    fails(
        "pp 4\n0 0 0 0 0 1\n0 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n",
        1,
        "found them collinear",
    );
}

#[test]
fn non_numbers() {
    fails(
        "s 0 zero 0 1",
        1,
        "y of the sphere centre (a number), found `zero`",
    );
    fails(
        "b 0.1 0.2 blue",
        1,
        "the blue of the background colour (a number), found `blue`",
    );
    fails(
        "f 1 1 1 0.5 0.5 10 0 one",
        1,
        "the material's index_of_refraction (a number), found `one`",
    );
    fails(
        "v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle wide\n",
        5,
        "the camera's angle in degrees (a number)",
    );
    let long = format!("s 0 0 0 {}", "x".repeat(100));
    fails(long, 1, "…`");
}

#[test]
fn nan_and_infinity() {
    fails(
        "s 0 0 0 nan",
        1,
        "the sphere radius (a finite number), found `nan`",
    );
    fails(
        "s inf 0 0 1",
        1,
        "x of the sphere centre (a finite number), found `inf`",
    );
    fails("s 0 0 0 1e39", 1, "(a finite number), found `1e39`");
    fails(
        "p 3\n0 0 0\n1 NaN 0\n0 1 0\n",
        3,
        "y of polygon vertex 2 of 3 (a finite number)",
    );
    fails(
        "l 1 2 3 -infinity 0 0",
        1,
        "the red of the light colour (a finite number)",
    );
}

#[test]
fn empty_files() {
    fails(
        "",
        1,
        "at least one object (`s`, `p`, `pp` or `c`), found an empty file",
    );
    fails("# only a comment\n\n", 1, "found an empty file");
    fails(
        "b 0 0 0\nl 1 1 1\n",
        2,
        "at least one object (`s`, `p`, `pp` or `c`), found none",
    );
}

#[test]
fn binary_garbage() {
    fails(
        [0x7f, b'E', b'L', b'F', 2, 1, 1, 0, 0xff, 0xfe],
        1,
        "found binary data (7f 45 4c 46 02 01 01 00)",
    );
    fails(
        b"s 0 0 0 1\n\xff\xfe\x00\x01",
        2,
        "an NFF keyword (v, b, l, f, s, p, pp, c), found binary data",
    );
    fails(
        b"s 0 0 \xc3\x28 1",
        1,
        "z of the sphere centre (a number), found binary data",
    );
}

#[test]
fn bad_entities() {
    fails(
        "s 0 0 0 1\nq 1 2 3\n",
        2,
        "an NFF keyword (v, b, l, f, s, p, pp, c), found `q`",
    );
    fails("s 0 0 0 0", 1, "a non-zero sphere radius, found 0");
    fails("c 0 0 0 1 0 0 0 0.5", 1, "distinct base and apex centres");
    fails("c 0 0 0 -1 0 1 0 0.5", 1, "a radius ≥ 0, found -1");
    fails(
        "c 0 0 0 0 0 1 0 0",
        1,
        "a cone with distinct base and apex centres and a radius > 0",
    );
}

const CAMERA_TAIL: &str = "hither 0.1\nresolution 32 32\ns 0 0 0 1\n";

#[test]
fn bad_cameras() {
    let camera = |from: &str, up: &str, angle: &str| {
        format!("# camera\nv\nfrom {from}\nat 0 0 0\nup {up}\nangle {angle}\n{CAMERA_TAIL}")
    };
    fails(
        camera("0 0 0", "0 1 0", "45"),
        2,
        "a usable camera, found one where camera eye and look-at point coincide",
    );
    fails(camera("0 0 5", "0 0 1", "45"), 2, "up vector is zero or parallel");
    fails(
        camera("0 0 5", "0 1 0", "180"),
        6,
        "a camera angle in (0°, 180°), found 180",
    );
    fails(camera("0 0 5", "0 1 0", "-5"), 6, "found -5");
    let missing_hither = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nresolution 32 32\n";
    fails(
        missing_hither,
        6,
        "`hither` (the camera's `v` entity lists from, at, up, angle, hither, resolution), found `resolution`",
    );
    let one_row = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\nresolution 32 1\ns 0 0 0 1\n";
    fails(one_row, 7, "the image height (an integer ≥ 2), found `1`");
    let twice = camera("0 0 5", "0 1 0", "45").replace("s 0 0 0 1", "v\nfrom 0 0 5\n");
    fails(
        twice,
        9,
        "one camera (`v`), found a second one (the first is on line 2)",
    );
}

#[test]
fn errors_through_scene_load_name_the_file() {
    let dir = Scratch::new("nff-load");
    let path = dir.write("broken.NFF", "s 0 0 0 1\n\n\np 2\n");
    let e = scene::load(&path).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}:4: expected the polygon's vertex count (an integer ≥ 3), found `2`",
            path.display()
        )
    );
    let missing = dir.path().join("missing.nff");
    let e = scene::load(&missing).unwrap_err();
    assert!(
        e.to_string()
            .starts_with(&format!("{}: cannot read", missing.display())),
        "{e}"
    );
    let good = dir.write("good.nff", EVERY_ENTITY);
    assert_eq!(scene::load(&good).unwrap().primitives.len(), 6);
}

#[test]
fn zero_area_patches_keep_their_index() {
    // A degenerate patch (two equal vertices) still takes index 0, so the sphere is 1.
    let s = parse("pp 3\n0 0 0 0 0 1\n0 0 0 0 0 1\n1 1 0 0 0 0\ns 0 0 -5 1\n").unwrap();
    assert_eq!(s.primitives.len(), 2);
    assert_eq!(s.primitives[0].bounds(), None);
    assert_eq!(s.vertex_normals[&0], [Vec3::Z, Vec3::Z, Vec3::ZERO]);
    let hit = BruteForce::new(&s.primitives).intersect(&Ray::unbounded(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z));
    assert_eq!((hit.prim, hit.t), (1, 9.0));
}
