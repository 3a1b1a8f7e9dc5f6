//! PLY loading: ASCII, binary little- and big-endian, gzip; the right counts,
//! vertices and face order; every malformed input an error naming file and line
//! (or element and index for binary bodies), never a panic.

use std::path::{Path, PathBuf};

use glam::Vec3;
use raypack::geometry::{Primitive, PrimitiveKind};
use raypack::rng::Rng;
use raypack::scene::{self, Scene, ply};

use crate::support::kernel::{assert_same_geometry, triangle_vertices};
use crate::{PYRAMID_KINDS, assert_error, data, kinds};

/// The square pyramid of `tests/data/pyramid_*.ply`.
const PYRAMID: [[f32; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.5, 0.5, 1.0],
];

fn v(i: usize) -> Vec3 {
    Vec3::from_array(PYRAMID[i])
}

/// The body encodings a test PLY can be written in.
#[derive(Clone, Copy, Debug)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

const ENCODINGS: [Encoding; 3] = [Encoding::Ascii, Encoding::Little, Encoding::Big];

/// A PLY file of float positions and `uchar`/`int` face lists, with an extra
/// `double` vertex property and an extra element to skip.
fn ply_bytes(encoding: Encoding, vertices: &[[f32; 3]], faces: &[Vec<i32>]) -> Vec<u8> {
    let format = match encoding {
        Encoding::Ascii => "ascii",
        Encoding::Little => "binary_little_endian",
        Encoding::Big => "binary_big_endian",
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty double quality\n\
         property float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\n\
         element note 1\nproperty list int short values\nend_header\n",
        vertices.len(),
        faces.len()
    )
    .into_bytes();
    let put = |out: &mut Vec<u8>, le: Vec<u8>| match encoding {
        Encoding::Big => out.extend(le.iter().rev()),
        _ => out.extend(le),
    };
    for p in vertices {
        match encoding {
            Encoding::Ascii => out.extend(format!("{} 0.25 {} {}\n", p[0], p[1], p[2]).bytes()),
            _ => {
                put(&mut out, p[0].to_le_bytes().to_vec());
                put(&mut out, 0.25f64.to_le_bytes().to_vec());
                put(&mut out, p[1].to_le_bytes().to_vec());
                put(&mut out, p[2].to_le_bytes().to_vec());
            }
        }
    }
    for f in faces {
        match encoding {
            Encoding::Ascii => {
                let ids: Vec<String> = f.iter().map(i32::to_string).collect();
                out.extend(format!("{} {}\n", f.len(), ids.join(" ")).bytes());
            }
            _ => {
                out.push(f.len() as u8);
                for i in f {
                    put(&mut out, i.to_le_bytes().to_vec());
                }
            }
        }
    }
    match encoding {
        Encoding::Ascii => out.extend(b"2 -7 9\n"),
        _ => {
            put(&mut out, 2i32.to_le_bytes().to_vec());
            put(&mut out, (-7i16).to_le_bytes().to_vec());
            put(&mut out, 9i16.to_le_bytes().to_vec());
        }
    }
    out
}

fn pyramid_faces() -> Vec<Vec<i32>> {
    vec![
        vec![0, 3, 2, 1],
        vec![0, 1, 4],
        vec![1, 2, 4],
        vec![2, 3, 4],
        vec![3, 0, 4],
    ]
}

fn parse(bytes: &[u8]) -> Result<Scene, String> {
    ply::parse(Path::new("test.ply"), bytes).map_err(|e| e.to_string())
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(bytes).unwrap();
    enc.finish().unwrap()
}

/// Check the pyramid: a quad base then 4 triangles, in file order.
fn check_pyramid(scene: &Scene) {
    assert_eq!(kinds(scene), PYRAMID_KINDS);
    assert_eq!(triangle_vertices(&scene.primitives[1]), [v(0), v(1), v(4)]);
    assert_eq!(triangle_vertices(&scene.primitives[2]), [v(1), v(2), v(4)]);
    assert_eq!(triangle_vertices(&scene.primitives[4]), [v(3), v(0), v(4)]);
    let Primitive::Polygon(base) = &scene.primitives[0] else {
        unreachable!()
    };
    assert_eq!(
        base.normal(),
        -Vec3::Z,
        "base faces down, counter-clockwise from below"
    );
    assert_eq!(scene.material_of, [0; 5]);
    assert_eq!(scene.materials.len(), 1);
}

#[test]
fn every_encoding_reads_the_same_mesh() {
    let reference = parse(&ply_bytes(Encoding::Ascii, &PYRAMID, &pyramid_faces())).unwrap();
    check_pyramid(&reference);
    for encoding in ENCODINGS {
        let bytes = ply_bytes(encoding, &PYRAMID, &pyramid_faces());
        let scene = parse(&bytes).unwrap_or_else(|e| panic!("{encoding:?}: {e}"));
        assert_same_geometry(&scene, &reference);
        let zipped = parse(&gzip(&bytes)).unwrap_or_else(|e| panic!("{encoding:?} gzip: {e}"));
        assert_same_geometry(&zipped, &reference);
        assert!(scene.vertex_normals.is_empty(), "no nx ny nz, no shading normals");
    }
}

#[test]
fn files_on_disk_load_by_extension_with_normals() {
    let reference = scene::load(&data("pyramid_ascii.ply")).unwrap();
    check_pyramid(&reference);
    // Triangles get the per-vertex normals; the quad base has none.
    assert_eq!(reference.vertex_normals.len(), 4);
    let down = Vec3::new(0.0, 0.0, -1.0);
    assert_eq!(reference.vertex_normals[&1], [down, down, Vec3::Z]);
    assert!(!reference.vertex_normals.contains_key(&0));
    for name in ["pyramid_le.ply", "pyramid_be.ply", "pyramid_ascii.ply.gz"] {
        let scene = scene::load(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_same_geometry(&scene, &reference);
        assert_eq!(scene.vertex_normals, reference.vertex_normals, "{name}");
        assert!(scene.source.ends_with(name));
    }
}

#[test]
fn loading_twice_gives_identical_geometry() {
    for name in ["pyramid_ascii.ply", "pyramid_le.ply", "pyramid_ascii.ply.gz"] {
        let a = scene::load(&data(name)).unwrap();
        let b = scene::load(&data(name)).unwrap();
        assert_same_geometry(&a, &b);
        assert_eq!(a.vertex_normals, b.vertex_normals);
    }
}

#[test]
fn crlf_headers_and_blank_body_lines_are_fine() {
    let text = "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\n\
                property float z\r\nelement face 1\r\nproperty list uchar uint vertex_index\r\nend_header\r\n\
                0 0 0\r\n\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n";
    let scene = parse(text.as_bytes()).unwrap();
    assert_eq!(
        triangle_vertices(&scene.primitives[0]),
        [Vec3::ZERO, Vec3::X, Vec3::Y]
    );
}

#[test]
fn header_errors_name_their_line() {
    assert_error(parse(b""), "test.ply:1: ", "empty file");
    assert_error(parse(b"PLY\n"), "test.ply:1: ", "not a PLY file");
    assert_error(parse(b"\x89PNG\r\n\x1a\n"), "test.ply:1: ", "not a PLY file");
    assert_error(
        parse(b"ply\nformat ascii 1.0\nelement vertex 1\n"),
        "test.ply:4: ",
        "`end_header` missing",
    );
    assert_error(
        parse(b"ply\nformat utf8 1.0\nend_header\n"),
        "test.ply:2: ",
        "unknown format `utf8`",
    );
    assert_error(
        parse(b"ply\nformat ascii 2.0\nend_header\n"),
        "test.ply:2: ",
        "format <encoding> 1.0",
    );
    assert_error(
        parse(b"ply\nformat ascii 1.0\nend_header\n"),
        "test.ply:3: ",
        "no `vertex` element",
    );
    assert_error(
        parse(b"ply\nformat ascii 1.0\nelement vertex -3\nend_header\n"),
        "test.ply:3: ",
        "not a count",
    );
    assert_error(
        parse(b"ply\nformat ascii 1.0\nelement vertex x\nend_header\n"),
        "test.ply:3: ",
        "not a count",
    );
    assert_error(
        parse(b"ply\nformat ascii 1.0\nproperty float x\nend_header\n"),
        "test.ply:3: ",
        "before any",
    );
    assert_error(
        parse(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty flaot x\nend_header\n"),
        "test.ply:4: ",
        "unknown property type `flaot`",
    );
    assert_error(
        parse(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\nend_header\n"),
        "test.ply:4: ",
        "integer type",
    );
    assert_error(
        parse(b"ply\nformat ascii 1.0\nvertex 3\nend_header\n"),
        "test.ply:3: ",
        "unknown header line",
    );
    let no_z = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                 element face 0\nproperty list uchar int vertex_indices\nend_header\n";
    assert_error(parse(no_z), "test.ply:3: ", "no property `z`");
    let points = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                   property float z\nend_header\n0 0 0\n";
    assert_error(parse(points), "test.ply:7: ", "no `face` element");
    let float_indices = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                          property float z\nelement face 1\nproperty list uchar float vertex_indices\nend_header\n";
    assert_error(parse(float_indices), "test.ply:8: ", "list of integers");
    let faces_first = b"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n\
                        element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    assert_error(parse(faces_first), "test.ply:3: ", "before the `vertex` element");
}

/// An ASCII pyramid with line `line` (1-based in the whole file) replaced.
fn ascii_with_line(line: usize, replacement: &str) -> Vec<u8> {
    let text = String::from_utf8(ply_bytes(Encoding::Ascii, &PYRAMID, &pyramid_faces())).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[line - 1] = replacement;
    (lines.join("\n") + "\n").into_bytes()
}

/// Line of the first vertex in [`ply_bytes`] output.
const FIRST_VERTEX_LINE: usize = 13;

#[test]
fn ascii_body_errors_name_line_element_and_index() {
    let line = FIRST_VERTEX_LINE + 2;
    assert_error(
        parse(&ascii_with_line(line, "1 0.25 1")),
        &format!("test.ply:{line}: vertex 2: "),
        "too few",
    );
    assert_error(
        parse(&ascii_with_line(line, "1 0.25 1 0 5")),
        &format!("test.ply:{line}: vertex 2: "),
        "unexpected value `5`",
    );
    assert_error(
        parse(&ascii_with_line(line, "1 0.25 one 0")),
        &format!("test.ply:{line}: vertex 2: "),
        "`y`: `one` is not a number",
    );
    for bad in ["nan", "inf", "-inf", "1e39"] {
        assert_error(
            parse(&ascii_with_line(line, &format!("1 0.25 {bad} 0"))),
            &format!("test.ply:{line}: vertex 2: "),
            "non-finite position",
        );
    }
    let face = FIRST_VERTEX_LINE + 5 + 1;
    let prefix = format!("test.ply:{face}: face 1: ");
    assert_error(
        parse(&ascii_with_line(face, "3 0 1 5")),
        &prefix,
        "index 5 out of range (5 vertices)",
    );
    assert_error(
        parse(&ascii_with_line(face, "3 0 -1 4")),
        &prefix,
        "index -1 out of range",
    );
    assert_error(
        parse(&ascii_with_line(face, "2 0 1")),
        &prefix,
        "at least 3 corners, got 2",
    );
    assert_error(
        parse(&ascii_with_line(face, "3 0 1.5 4")),
        &prefix,
        "`1.5` is not an integer",
    );
    assert_error(
        parse(&ascii_with_line(face, "300 0 1 4")),
        &prefix,
        "300 does not fit its type (0 to 255)",
    );
    assert_error(parse(&ascii_with_line(face, "4 0 1 4")), &prefix, "too few");
    // The skipped element is checked too.
    let note = FIRST_VERTEX_LINE + 5 + 5;
    assert_error(
        parse(&ascii_with_line(note, "2 -7 99999")),
        &format!("test.ply:{note}: note 0: "),
        "does not fit",
    );
}

#[test]
fn wrong_counts_and_truncation_are_caught_in_ascii() {
    let good = String::from_utf8(ply_bytes(Encoding::Ascii, &PYRAMID, &pyramid_faces())).unwrap();
    // The header promises one vertex more: the first face line (a quad, 5
    // values for 4 properties) is read as a vertex.
    let more = good.replace("element vertex 5", "element vertex 6");
    assert_error(
        parse(more.as_bytes()),
        &format!("test.ply:{}: vertex 5: ", FIRST_VERTEX_LINE + 5),
        "too many",
    );
    // One vertex fewer: the last vertex line is read as a face.
    let fewer = good.replace("element vertex 5", "element vertex 4");
    assert_error(
        parse(fewer.as_bytes()),
        &format!("test.ply:{}: face 0: ", FIRST_VERTEX_LINE + 4),
        "",
    );
    // Cut after the second face: the error points past the last line.
    let lines: Vec<&str> = good.lines().collect();
    let cut = lines[..FIRST_VERTEX_LINE + 6].join("\n") + "\n";
    assert_error(
        parse(cut.as_bytes()),
        &format!("test.ply:{}: face 2: ", FIRST_VERTEX_LINE + 7),
        "unexpected end of file",
    );
    // Data after the last element.
    let extra = good.clone() + "1 2 3\n";
    assert_error(
        parse(extra.as_bytes()),
        &format!("test.ply:{}: ", FIRST_VERTEX_LINE + 11),
        "after the last element",
    );
    // An empty face element.
    let none = "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n\
                element face 0\nproperty list uchar int vertex_indices\nend_header\n";
    assert_error(parse(none.as_bytes()), "test.ply:9: ", "0 faces");
}

#[test]
fn binary_errors_name_element_and_index() {
    for encoding in [Encoding::Little, Encoding::Big] {
        let good = ply_bytes(encoding, &PYRAMID, &pyramid_faces());
        let mut faces = pyramid_faces();
        faces[3][1] = 99_999;
        assert_error(
            parse(&ply_bytes(encoding, &PYRAMID, &faces)),
            "test.ply: face 3: ",
            "index 99999 out of range (5 vertices)",
        );
        faces[3] = vec![1, 2];
        assert_error(
            parse(&ply_bytes(encoding, &PYRAMID, &faces)),
            "test.ply: face 3: ",
            "got 2",
        );
        let mut vertices = PYRAMID;
        vertices[4][2] = f32::NAN;
        assert_error(
            parse(&ply_bytes(encoding, &vertices, &pyramid_faces())),
            "test.ply: vertex 4: ",
            "non-finite",
        );
        vertices[4][2] = f32::INFINITY;
        assert_error(
            parse(&ply_bytes(encoding, &vertices, &pyramid_faces())),
            "test.ply: vertex 4: ",
            "non-finite",
        );
        // Trailing garbage.
        let mut extra = good.clone();
        extra.extend(b"\x01\x02");
        assert_error(parse(&extra), "test.ply: ", "2 bytes of unexpected data");
        // Trailing white space is harmless.
        let mut newline = good.clone();
        newline.push(b'\n');
        assert!(parse(&newline).is_ok());
    }
}

#[test]
fn every_binary_truncation_is_an_error_naming_element_and_index() {
    for encoding in [Encoding::Little, Encoding::Big] {
        let good = ply_bytes(encoding, &PYRAMID, &pyramid_faces());
        let body = good.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        for cut in body..good.len() {
            let err = parse(&good[..cut]).expect_err("a truncated file must not load");
            let named = ["vertex ", "face ", "note 0"]
                .iter()
                .any(|e| err.starts_with(&format!("test.ply: {e}")));
            assert!(
                named && err.contains("unexpected end of data"),
                "cut {cut}: {err}"
            );
        }
        // And truncation of the gzip stream itself.
        let zipped = gzip(&good);
        assert_error(parse(&zipped[..zipped.len() / 2]), "test.ply: ", "gzip");
    }
}

#[test]
fn binary_garbage_never_panics() {
    let mut rng = Rng::new(7);
    let good = ply_bytes(Encoding::Little, &PYRAMID, &pyramid_faces());
    let body = good.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    for round in 0..3000 {
        // Random bytes after a valid header, or a valid file with bytes flipped.
        let bytes = if round % 2 == 0 {
            let n = rng.below(200) as usize;
            let mut b = good[..body].to_vec();
            b.extend((0..n).map(|_| rng.next_u32() as u8));
            b
        } else {
            let mut b = good.clone();
            for _ in 0..=rng.below(4) {
                let at = rng.below(b.len() as u32) as usize;
                b[at] = rng.next_u32() as u8;
            }
            b
        };
        if let Err(e) = parse(&bytes) {
            assert!(e.starts_with("test.ply"), "{e}");
        }
    }
    // Pure noise is not a PLY file.
    let noise: Vec<u8> = (0..4096).map(|_| rng.next_u32() as u8).collect();
    assert_error(parse(&noise), "test.ply:1: ", "not a PLY file");
}

/// An asset fetched by `scripts/fetch-assets.sh`. The tests that need one are
/// `#[ignore]`d (shown as ignored by `cargo test`); `.ci/run` fetches the assets
/// and runs them with `--include-ignored`, where a missing asset is a failure.
fn asset(name: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets").join(name);
    assert!(
        path.exists(),
        "{} is absent: run scripts/fetch-assets.sh",
        path.display()
    );
    path
}

#[test]
#[ignore = "needs assets: run scripts/fetch-assets.sh, then cargo test -- --include-ignored"]
fn stanford_dragon_has_871414_triangles_in_binary_and_ascii() {
    let binary = asset("dragon.ply");
    let dragon = scene::load(&binary).unwrap();
    assert_eq!(dragon.primitives.len(), 871_414);
    assert_eq!(dragon.counts(), [(PrimitiveKind::Triangle, 871_414)]);
    let b = dragon.bounds();
    assert!(
        b.extent().max_element() > 0.1 && b.extent().max_element() < 1.0,
        "{b:?}"
    );
    let original = scene::load(&asset("dragon_vrip.ply.gz")).unwrap();
    assert_same_geometry(&original, &dragon);
}

#[test]
#[ignore = "needs assets: run scripts/fetch-assets.sh, then cargo test -- --include-ignored"]
fn dragon_decimations_and_bunny_load() {
    for (name, faces) in [
        ("dragon_res2.ply", 202_520),
        ("dragon_res3.ply", 47_794),
        ("dragon_res4.ply", 11_102),
        ("bunny.ply", 3_674),
    ] {
        let mesh = scene::load(&asset(name)).unwrap();
        assert_eq!(mesh.primitives.len(), faces, "{name}");
        assert!(
            mesh.primitives
                .iter()
                .all(|p| p.kind() == PrimitiveKind::Triangle)
        );
    }
}
