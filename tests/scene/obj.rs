//! OBJ loading: faces in file order (quads stay one polygon), negative indices,
//! normals; every malformed input an error naming file and line, never a panic.

use std::path::Path;

use glam::Vec3;
use raypack::geometry::{Primitive, PrimitiveKind};
use raypack::rng::Rng;
use raypack::scene::{self, Scene, obj};

use crate::support::kernel::{assert_same_geometry, triangle_vertices};
use crate::{PYRAMID_KINDS, assert_error, data, kinds};

fn parse(text: &[u8]) -> Result<Scene, String> {
    obj::parse(Path::new("test.obj"), text).map_err(|e| e.to_string())
}

#[test]
fn pyramid_with_a_quad_normals_and_relative_indices() {
    let scene = scene::load(&data("pyramid.obj")).unwrap();
    assert_eq!(kinds(&scene), PYRAMID_KINDS);
    let apex = Vec3::new(0.5, 0.5, 1.0);
    let corner = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    assert_eq!(
        triangle_vertices(&scene.primitives[1]),
        [corner(0.0, 0.0), corner(1.0, 0.0), apex]
    );
    // `f -4//1 -3//1 -1//2` after 5 vertices: vertices 2, 3 and 5.
    assert_eq!(
        triangle_vertices(&scene.primitives[2]),
        [corner(1.0, 0.0), corner(1.0, 1.0), apex]
    );
    assert_eq!(
        triangle_vertices(&scene.primitives[4]),
        [corner(0.0, 1.0), corner(0.0, 0.0), apex]
    );
    let Primitive::Polygon(base) = &scene.primitives[0] else {
        unreachable!()
    };
    assert_eq!(base.normal(), -Vec3::Z);
    // Normals where all three corners name one: faces 1 and 2.
    let down = -Vec3::Z;
    assert_eq!(scene.vertex_normals.len(), 2);
    assert_eq!(scene.vertex_normals[&1], [down, down, Vec3::Z]);
    assert_eq!(scene.vertex_normals[&2], [down, down, Vec3::Z]);
}

#[test]
fn obj_and_ply_of_one_mesh_agree() {
    let obj = scene::load(&data("pyramid.obj")).unwrap();
    let ply = scene::load(&data("pyramid_ascii.ply")).unwrap();
    assert_same_geometry(&obj, &ply);
}

#[test]
fn loading_twice_gives_identical_geometry() {
    let a = scene::load(&data("pyramid.obj")).unwrap();
    let b = scene::load(&data("pyramid.obj")).unwrap();
    assert_same_geometry(&a, &b);
    assert_eq!(a.vertex_normals, b.vertex_normals);
}

#[test]
fn gzip_crlf_comments_and_vertex_colours_are_read() {
    use std::io::Write;
    let text = b"# a triangle\r\nv 0 0 0 1 0 0\r\nv 1 0 0 0 1 0\r\nv 0 1 0 1.0 # w\r\nf 1 2 3 # done\r\n";
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(text).unwrap();
    for bytes in [text.to_vec(), enc.finish().unwrap()] {
        let scene = parse(&bytes).unwrap();
        assert_eq!(
            triangle_vertices(&scene.primitives[0]),
            [Vec3::ZERO, Vec3::X, Vec3::Y]
        );
    }
}

#[test]
fn faces_stay_in_file_order_across_groups() {
    let mut text = String::new();
    for i in 0..50 {
        text += &format!("g group{}\nv {i} 0 0\nv {i} 1 0\nv {i} 0 1\nf -3 -2 -1\n", i % 3);
    }
    let scene = parse(text.as_bytes()).unwrap();
    assert_eq!(scene.primitives.len(), 50);
    for (i, p) in scene.primitives.iter().enumerate() {
        assert_eq!(triangle_vertices(p)[0].x, i as f32, "face {i} out of order");
    }
}

#[test]
fn malformed_statements_name_their_line() {
    let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let with = |line: &str| format!("{head}{line}\n").into_bytes();
    assert_error(
        parse(&with("f 1 2 4")),
        "test.obj:4: ",
        "vertex index 4 out of range (3 vertices defined so far)",
    );
    assert_error(
        parse(&with("f 1 2 -4")),
        "test.obj:4: ",
        "vertex index -4 out of range",
    );
    assert_error(parse(&with("f 1 2 0")), "test.obj:4: ", "index 0 is not valid");
    assert_error(parse(&with("f 1 2")), "test.obj:4: ", "at least 3 corners, got 2");
    assert_error(parse(&with("f 1 2 x")), "test.obj:4: ", "`x` is not an integer");
    assert_error(parse(&with("f 1 2 3/a")), "test.obj:4: ", "`a` is not an integer");
    assert_error(
        parse(&with("f 1//1 2//1 3//1")),
        "test.obj:4: ",
        "normal index 1 out of range (0 normals",
    );
    assert_error(
        parse(&with("f 1/1/1/1 2 3")),
        "test.obj:4: ",
        "not v, v/vt, v//vn or v/vt/vn",
    );
    assert_error(parse(&with("v 1 2")), "test.obj:4: ", "got 2 numbers");
    assert_error(parse(&with("v 1 2 3 4 5")), "test.obj:4: ", "got 5 numbers");
    assert_error(
        parse(&with("v 1 2 3 4 5 6 7")),
        "test.obj:4: ",
        "more than 6 numbers",
    );
    assert_error(parse(&with("v 1 two 3")), "test.obj:4: ", "`two` is not a number");
    assert_error(
        parse(&with("vn 1 0")),
        "test.obj:4: ",
        "`vn` needs 3 numbers, got 2",
    );
    for bad in ["nan", "inf", "-infinity", "1e40"] {
        assert_error(
            parse(&with(&format!("v 0 {bad} 0"))),
            "test.obj:4: ",
            "not a finite number",
        );
        assert_error(
            parse(&with(&format!("vn 0 {bad} 0"))),
            "test.obj:4: ",
            "not a finite number",
        );
    }
    assert_error(
        parse(&with("curv 0 1 1 2")),
        "test.obj:4: ",
        "unknown statement `curv`",
    );
}

#[test]
fn empty_files_and_files_without_faces_are_errors() {
    assert_error(parse(b""), "test.obj:1: ", "no faces");
    assert_error(parse(b"# nothing\n\n"), "test.obj:3: ", "no faces");
    assert_error(
        parse(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
        "test.obj:4: ",
        "no faces: expected `f` statements (3 vertices read)",
    );
}

/// OBJ states no counts, so a file cut at a line or token boundary is a valid
/// shorter file (`f 1 4 3 2` cut to `f 1 4 3` is a triangle): loading it must
/// fail with a line, or give the same faces as the whole file except the last.
#[test]
fn truncated_files_fail_or_keep_every_complete_face() {
    let text = std::fs::read(data("pyramid.obj")).unwrap();
    let full = parse(&text).unwrap();
    for cut in 0..text.len() {
        match parse(&text[..cut]) {
            Err(e) => assert!(e.starts_with("test.obj:"), "cut {cut}: {e}"),
            Ok(scene) => {
                let n = scene.primitives.len();
                assert!(n <= full.primitives.len(), "cut {cut}");
                assert_eq!(scene.primitives[..n - 1], full.primitives[..n - 1], "cut {cut}");
            }
        }
    }
}

#[test]
fn binary_garbage_is_an_error_not_a_panic() {
    let mut rng = Rng::new(11);
    for _ in 0..2000 {
        let n = 1 + rng.below(300) as usize;
        let bytes: Vec<u8> = (0..n).map(|_| rng.next_u32() as u8).collect();
        let err = parse(&bytes).expect_err("noise is not a mesh");
        assert!(err.starts_with("test.obj:"), "{err}");
    }
    assert_error(
        parse(b"\x00\x01\x02\xff v 0 0 0\n"),
        "test.obj:1: ",
        "unknown statement `\\0\\u{1}\\u{2}\u{fffd}`",
    );
}

#[test]
#[ignore = "needs assets: run scripts/fetch-assets.sh, then cargo test -- --include-ignored"]
fn teapot_asset_loads() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/teapot.obj");
    assert!(
        path.exists(),
        "{} is absent: run scripts/fetch-assets.sh",
        path.display()
    );
    let teapot = scene::load(&path).unwrap();
    assert_eq!(teapot.primitives.len(), 992);
    assert!(
        teapot
            .primitives
            .iter()
            .all(|p| p.kind() == PrimitiveKind::Triangle)
    );
}
