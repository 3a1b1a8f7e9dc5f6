//! The native TOML reader: every object type, transforms and includes on good
//! files, and malformed files, each failing with `file:line:` on the right line.

use crate::support::scratch::Scratch;
use glam::{Mat4, Quat, Vec3};
use raypack::accel::{Accel, BruteForce};
use raypack::geometry::{Plane as PlaneForm, Primitive, PrimitiveKind};
use raypack::ray::Ray;
use raypack::scene::{self, Material, Scene, SceneError, loader, native};
use std::path::Path;

const EVERY_OBJECT: &str = r#"
background = [0.1, 0.2, 0.3]

[camera]
eye = [0, 1, 10]
center = [0, 1, 0]
fovx = 70
fovy = 50
width = 320
height = 200

[materials.red]
color = [1, 0, 0]
ks = 0.5

[materials.glass]
transmittance = 0.9
ior = 1.5

[[lights]]
position = [1, 2, 3]

[[lights]]
position = [-1, 2, 3]
color = [0.5, 0.5, 0.5]

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "red"

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 2
inside_only = true

[[objects]]
type = "plane"
implicit = [0, 1, 0, 1]

[[objects]]
type = "plane"
point = [0, -1, 0]
normal = [0, 2, 0]

[[objects]]
type = "plane"
origin = [0, -1, 0]
i = [0, 0, 1]
j = [1, 0, 0]

[[objects]]
type = "triangle"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
normals = [[0, 0, 1], [0, 0, 2], [0, 1, 1]]
material = "glass"

[[objects]]
type = "polygon"
vertices = [[0, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0]]

[[objects]]
type = "cone"
base = [0, 0, 0]
base_radius = 1
apex = [0, 2, 0]
apex_radius = 0
"#;

fn parse(text: &str) -> Result<Scene, SceneError> {
    scene::parse(Path::new("test.toml"), text.as_bytes())
}

#[test]
fn every_object_type_is_read() {
    let s = parse(EVERY_OBJECT).unwrap();
    use PrimitiveKind::*;
    let kinds = crate::kinds(&s);
    assert_eq!(
        kinds,
        [Sphere, Sphere, Plane, Plane, Plane, Triangle, Polygon, Cone]
    );
    assert!(matches!(
        s.primitives[2],
        Primitive::Plane(PlaneForm::Implicit(_))
    ));
    assert!(matches!(
        s.primitives[3],
        Primitive::Plane(PlaneForm::PointNormal(_))
    ));
    assert!(matches!(
        s.primitives[4],
        Primitive::Plane(PlaneForm::Parametric(_))
    ));
    let Primitive::Sphere(inside) = &s.primitives[1] else {
        panic!()
    };
    assert!(inside.inside_only);
    // Materials: named ones in name order, then the default one on first use.
    assert_eq!(s.materials.len(), 3);
    assert_eq!(s.materials[s.material_of[0] as usize].color, Vec3::X);
    assert_eq!(s.materials[s.material_of[0] as usize].ks, 0.5);
    assert_eq!(s.materials[s.material_of[5] as usize].ior, 1.5);
    assert_eq!(s.materials[s.material_of[1] as usize], Material::default());
    assert_eq!(s.material_of[1], s.material_of[7]);
    // Lights, camera, background.
    assert_eq!(s.lights.len(), 2);
    assert_eq!(s.lights[0].color, Vec3::ONE);
    assert_eq!(s.lights[1].color, Vec3::splat(0.5));
    let cam = s.camera.unwrap();
    assert_eq!(
        (cam.fovx, cam.fovy, cam.width, cam.height, cam.up),
        (70.0, 50.0, 320, 200, Vec3::Y)
    );
    assert_eq!(s.background, Vec3::new(0.1, 0.2, 0.3));
    // Smooth triangle normals are normalised.
    let n = s.vertex_normals[&5];
    assert_eq!([n[0], n[1]], [Vec3::Z, Vec3::Z]);
    assert!((n[2] - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);
    // The three plane forms describe the same plane y = -1.
    for i in 2..5 {
        let r = Ray::unbounded(Vec3::new(0.3, 5.0, 0.2), -Vec3::Y);
        let accel = BruteForce::new(&s.primitives[i..i + 1]);
        assert_eq!(accel.intersect(&r).t, 6.0, "plane {i}");
    }
}

#[test]
fn loading_twice_gives_identical_geometry() {
    let (a, b) = (parse(EVERY_OBJECT).unwrap(), parse(EVERY_OBJECT).unwrap());
    assert_eq!(a.primitives, b.primitives);
    assert_eq!((a.material_of, a.materials), (b.material_of, b.materials));
    assert_eq!(a.vertex_normals, b.vertex_normals);
}

/// One object of `body` under a transform, and the nearest hit of a ray.
fn hit_t(object: &str, transform: &str, origin: Vec3, dir: Vec3) -> Option<f32> {
    let s = parse(&format!("[[objects]]\n{object}\ntransform = {transform}\n")).unwrap();
    let hit = BruteForce::new(&s.primitives).intersect(&Ray::unbounded(origin, dir.normalize()));
    hit.is_hit().then_some(hit.t)
}

#[test]
fn transforms_place_objects() {
    let sphere = "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1";
    // An ellipsoid: semi-axis 3 along x after the scale, moved to x = 10.
    let trs = "{ scale = [3, 1, 1], translate = [10, 0, 0] }";
    let near = |t: Option<f32>, want: f32| t.is_some_and(|t| (t - want).abs() < 1e-5);
    assert!(near(hit_t(sphere, trs, Vec3::ZERO, Vec3::X), 7.0));
    // Scale, then rotate 90° about z (the long axis turns to y), then translate.
    let turned = "{ scale = [3, 1, 1], rotate = { axis = [0, 0, 2], degrees = 90 }, translate = [0, 10, 0] }";
    let t = hit_t(sphere, turned, Vec3::ZERO, Vec3::Y).unwrap();
    assert!((t - 7.0).abs() < 1e-5, "{t}");
    // A uniform scale as a single number.
    assert!(near(
        hit_t(sphere, "{ scale = 2 }", Vec3::new(0.0, 0.0, 10.0), -Vec3::Z),
        8.0
    ));
    // A row-major matrix: the translation sits in the last column.
    let matrix = "{ matrix = [[1, 0, 0, 10], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]] }";
    assert!(near(hit_t(sphere, matrix, Vec3::ZERO, Vec3::X), 9.0));
    // Cones and planes become transformed primitives too.
    let cone = "type = \"cone\"\nbase = [0, 0, 0]\nbase_radius = 1\napex = [0, 1, 0]\napex_radius = 1";
    assert!(near(
        hit_t(
            cone,
            "{ translate = [5, 0, 0] }",
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::X
        ),
        4.0
    ));
    let plane = "type = \"plane\"\nimplicit = [0, 1, 0, 0]";
    assert!(near(
        hit_t(plane, "{ translate = [0, 3, 0] }", Vec3::ZERO, Vec3::Y),
        3.0
    ));
    let s = parse(&format!("[[objects]]\n{sphere}\ntransform = {trs}\n")).unwrap();
    assert_eq!(s.primitives[0].kind(), PrimitiveKind::Transformed);
}

#[test]
fn triangles_and_polygons_are_baked() {
    let text = r#"
[[objects]]
type = "triangle"
vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
normals = [[0, 0, 1], [0, 0, 1], [0, 0, 1]]
transform = { rotate = { axis = [0, 1, 0], degrees = 90 }, translate = [0, 0, -5] }

[[objects]]
type = "polygon"
vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
transform = { translate = [0, 0, 3] }
"#;
    let s = parse(text).unwrap();
    let Primitive::Triangle(t) = &s.primitives[0] else {
        panic!("{:?}", s.primitives[0])
    };
    let m = Mat4::from_rotation_translation(
        Quat::from_rotation_y(90f32.to_radians()),
        Vec3::new(0.0, 0.0, -5.0),
    );
    for (got, v) in t.vertices().iter().zip([Vec3::ZERO, Vec3::X, Vec3::Y]) {
        assert!((*got - m.transform_point3(v)).length() < 1e-6);
    }
    // The shading normals turn with the triangle: +z becomes +x.
    assert!((s.vertex_normals[&0][0] - Vec3::X).length() < 1e-6);
    assert_eq!(s.primitives[1].kind(), PrimitiveKind::Polygon);
    let hit = BruteForce::new(&s.primitives).intersect(&Ray::unbounded(Vec3::new(0.5, 0.5, 10.0), -Vec3::Z));
    assert_eq!((hit.prim, hit.t), (1, 7.0));
}

/// A TOML scene with includes (an NFF part, and a TOML file including it again).
const INCLUDE_FILES: [(&str, &str); 3] = [
    (
        "part.nff",
        "l 0 5 0 0.5 0.5 0.5\nf 0 1 0 1 0 0 0 1\npp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\ns 0 0 0 1\n",
    ),
    (
        "nested.toml",
        "[[objects]]\ntype = \"include\"\npath = \"part.nff\"\nkeep_lights = true\n",
    ),
    (
        "main.toml",
        r#"
[materials.blue]
color = [0, 0, 1]

[[objects]]
type = "sphere"
center = [0, 0, -20]
radius = 1

[[objects]]
type = "include"
path = "part.nff"
transform = { translate = [10, 0, 0] }
keep_lights = true

[[objects]]
type = "include"
path = "nested.toml"
material = "blue"

[[objects]]
type = "cone"
base = [0, 0, 0]
base_radius = 1
apex = [0, 1, 0]
apex_radius = 1
"#,
    ),
];

#[test]
fn includes_place_instances_with_materials_and_transforms() {
    let dir = Scratch::new("native-include");
    for (name, text) in INCLUDE_FILES {
        dir.write(name, text);
    }
    let main = dir.path().join("main.toml");
    let s = scene::load(&main).unwrap();
    use PrimitiveKind::*;
    // The file's own primitives; part.nff is one mesh, placed by the include
    // and, with the blue override, another mesh placed through nested.toml.
    assert_eq!(crate::kinds(&s), [Sphere, Cone]);
    let summary = s.instancing_summary().unwrap();
    assert_eq!((summary.instances, summary.meshes, summary.depth), (2, 2, 2));
    assert_eq!((summary.unique_primitives, summary.instanced_primitives), (6, 6));
    // Flattened, the instanced primitives follow under their ids: the
    // triangle baked, the sphere transformed.
    let flat = s.flattened().unwrap();
    let kinds: Vec<PrimitiveKind> = flat.primitives.iter().map(Primitive::kind).collect();
    assert_eq!(
        kinds,
        [Sphere, Cone, Triangle, Transformed, Triangle, Transformed]
    );
    let Primitive::Triangle(t) = &flat.primitives[2] else {
        panic!()
    };
    assert_eq!(t.vertices()[1], Vec3::new(11.0, 0.0, 0.0));
    let ray = Ray::unbounded(Vec3::new(10.0, 0.0, 5.0), -Vec3::Z);
    let hit = BruteForce::new(&flat.primitives).intersect(&ray);
    assert_eq!((hit.prim, hit.t), (3, 4.0));
    let instanced = raypack::accel::TwoLevel::new(&s, BruteForce::new).intersect(&ray);
    assert_eq!((instanced.prim, instanced.t), (3, 4.0));
    // Vertex normals follow their primitives' ids.
    let mut smooth: Vec<u32> = flat.vertex_normals.keys().copied().collect();
    smooth.sort();
    assert_eq!(smooth, [2, 4]);
    // Own material for the first include, the override for the nested one.
    assert_eq!(s.material(2).color, Vec3::Y);
    assert_eq!(s.material(4).color, Vec3::Z);
    assert_eq!(s.material(5).color, Vec3::Z);
    // Only the include that asked for them brings its lights, transformed.
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.lights[0].position, Vec3::new(10.0, 5.0, 0.0));
    // Loading twice gives the same geometry, includes and all.
    assert_eq!(
        scene::load(&main).unwrap().flattened().unwrap().primitives,
        flat.primitives
    );
}

/// Includes read from memory give the scene read from disk, and touch no file.
#[test]
fn includes_from_memory_give_the_scene_from_disk() {
    let dir = Scratch::new("native-include-memory");
    let mut files = loader::InMemory::new();
    for (name, text) in INCLUDE_FILES {
        dir.write(name, text);
        files.insert(dir.path().join(name), text);
    }
    let disk = scene::load(&dir.path().join("main.toml")).unwrap();
    // The same names, and names that are nowhere on disk.
    for root in [dir.path(), Path::new("mem/scenes")] {
        let mut files = files.clone();
        for (name, text) in INCLUDE_FILES {
            files.insert(root.join(name), text);
        }
        let memory = native::load_from(&root.join("./main.toml"), &files).unwrap();
        assert_eq!(memory.primitives, disk.primitives);
        let [memory_flat, disk_flat] = [&memory, &disk].map(|s| s.flattened().unwrap());
        assert_eq!(memory_flat.primitives, disk_flat.primitives);
        assert_eq!(memory_flat.material_of, disk_flat.material_of);
        assert_eq!(memory_flat.vertex_normals, disk_flat.vertex_normals);
        assert_eq!(memory.material_of, disk.material_of);
        assert_eq!(memory.materials, disk.materials);
        assert_eq!(memory.lights, disk.lights);
        assert_eq!(memory.vertex_normals, disk.vertex_normals);
    }
}

/// Named meshes: `instance` objects place a `[meshes]` file, read once; the
/// object's material overrides the mesh's; unknown names are errors at their line.
#[test]
fn instances_place_named_meshes() {
    let mut files = loader::InMemory::new();
    files.insert("part.nff", "f 0 1 0 1 0 0 0 1\np 3\n0 0 0\n1 0 0\n0 1 0\n");
    let main = r#"
[materials.blue]
color = [0, 0, 1]

[materials.red]
color = [1, 0, 0]

[meshes.part]
path = "part.nff"
material = "blue"

[[objects]]
type = "instance"
mesh = "part"

[[objects]]
type = "instance"
mesh = "part"
transform = { translate = [5, 0, 0] }

[[objects]]
type = "instance"
mesh = "part"
material = "red"
"#;
    files.insert("main.toml", main);
    let s = native::load_from(Path::new("main.toml"), &files).unwrap();
    let summary = s.instancing_summary().unwrap();
    assert_eq!(
        (summary.instances, summary.meshes),
        (3, 2),
        "one mesh per material"
    );
    assert_eq!(s.id_count(), 3);
    assert_eq!(s.material(0).color, Vec3::Z);
    assert_eq!(s.material(1).color, Vec3::Z);
    assert_eq!(s.material(2).color, Vec3::X);
    let moved = s.flattened().unwrap().primitives[1].bounds().unwrap();
    assert!(
        (moved.max - Vec3::new(6.0, 1.0, 0.0)).abs().max_element() < 1e-5,
        "{moved:?}"
    );

    let unknown = main.replace("mesh = \"part\"\ntransform", "mesh = \"prat\"\ntransform");
    files.insert("bad.toml", unknown.as_str());
    let e = native::load_from(Path::new("bad.toml"), &files).unwrap_err();
    assert_eq!(e.line, Some(18), "{e}");
    assert!(e.message.contains("[meshes] (part), found `prat`"), "{e}");
    let no_material = main.replace("material = \"blue\"", "material = \"green\"");
    files.insert("bad2.toml", no_material.as_str());
    let e = native::load_from(Path::new("bad2.toml"), &files).unwrap_err();
    assert_eq!(e.line, Some(10), "{e}");
    assert!(e.message.contains("found `green`"), "{e}");
}

/// In memory, cycles are found through `.` and `..`; a missing file is an
/// error at the include; and nesting stops at the documented depth.
#[test]
fn includes_from_memory_refuse_cycles_missing_files_and_deep_chains() {
    let include = |path: &str| format!("[[objects]]\ntype = \"include\"\npath = \"{path}\"\n");
    let mut files = loader::InMemory::new();
    files.insert("a.toml", include("sub/b.toml"));
    files.insert("sub/b.toml", include("../x/.././a.toml"));
    files.insert("m.toml", include("gone.nff"));
    let e = native::load_from(Path::new("a.toml"), &files).unwrap_err();
    assert!(
        e.message.contains("found a cycle through `../x/.././a.toml`"),
        "{e}"
    );
    assert_eq!(
        (e.path.as_path(), e.line),
        (Path::new("sub/b.toml"), Some(3)),
        "{e}"
    );
    let e = native::load_from(Path::new("m.toml"), &files).unwrap_err();
    assert_eq!((e.path.as_path(), e.line), (Path::new("m.toml"), Some(3)), "{e}");
    assert!(
        e.message.contains("expected a readable scene file at `gone.nff`"),
        "{e}"
    );
    let e = native::load_from(Path::new("none.toml"), &files).unwrap_err();
    assert_eq!(e.to_string(), "none.toml: cannot read: no such file in memory");

    // A chain d0 → d1 → … → dN, dN holding a sphere: N + 1 files deep.
    let chain = |files_deep: usize| {
        let mut files = loader::InMemory::new();
        for k in 0..files_deep - 1 {
            files.insert(format!("d{k}.toml"), include(&format!("d{}.toml", k + 1)));
        }
        files.insert(format!("d{}.toml", files_deep - 1), SPHERE);
        native::load_from(Path::new("d0.toml"), &files)
    };
    let deepest = chain(native::MAX_INCLUDE_DEPTH).unwrap();
    assert_eq!(deepest.id_count(), 1);
    assert_eq!(
        deepest.instancing_summary().unwrap().depth,
        native::MAX_INCLUDE_DEPTH as u32 - 1
    );
    let e = chain(native::MAX_INCLUDE_DEPTH + 1).unwrap_err();
    assert!(
        e.message.contains(&format!(
            "expected includes nested at most {} deep",
            native::MAX_INCLUDE_DEPTH
        )),
        "{e}"
    );
}

/// Parse `text` expecting an error on `line` whose message contains `needle`.
#[track_caller]
fn fails(text: &str, line: usize, needle: &str) {
    let e = scene::parse(Path::new("bad.toml"), text.as_bytes()).expect_err("must not load");
    let shown = e.to_string();
    assert_eq!(e.line, Some(line), "{shown}");
    assert!(shown.starts_with(&format!("bad.toml:{line}: ")), "{shown}");
    assert!(shown.contains(needle), "`{shown}` lacks `{needle}`");
}

const SPHERE: &str = "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n";

#[test]
fn toml_syntax_errors_and_truncation() {
    fails("[[objects]]\ntype = \"sphere\"\ncenter = [0, 0", 3, "");
    fails("[[objects]]\ntype = \"sphere\n", 2, "");
    fails(&format!("{SPHERE}\n[camera\n"), 6, "");
}

#[test]
fn wrong_types_and_unknown_keys() {
    fails(&format!("{SPHERE}radius2 = 3\n"), 5, "unknown field `radius2`");
    fails(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = \"big\"\n",
        4,
        "expected f64, found string \"big\"",
    );
    fails(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0]\nradius = 1\n",
        3,
        "expected an array of length 3, found length 2",
    );
    fails(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\n",
        1,
        "missing field `radius`",
    );
    fails(
        &format!("colour = [1, 1, 1]\n{SPHERE}"),
        1,
        "unknown field `colour`",
    );
    fails(
        "objects = 3\n",
        1,
        "expected `objects` to be an array of tables ([[objects]]), found another value",
    );
    fails("objects = [1]\n", 1, "expected each object to be a table");
    fails(
        &format!("{SPHERE}[[objects]]\ncenter = [0, 0, 0]\n"),
        5,
        "expected a `type` key",
    );
    fails(
        &format!("{SPHERE}[[objects]]\ntype = \"torus\"\n"),
        6,
        "expected an object type (sphere, plane, triangle, polygon, cone, include or instance), found `torus`",
    );
}

#[test]
fn nan_and_infinity() {
    fails(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, nan, 0]\nradius = 1\n",
        3,
        "expected a finite number, found NaN",
    );
    fails(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = inf\n",
        4,
        "expected a finite number, found inf",
    );
    fails(
        "[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1e39\n",
        4,
        "within ±3.4e38, found 1e39",
    );
    fails(&format!("background = [0, -inf, 0]\n{SPHERE}"), 1, "finite");
}

#[test]
fn empty_and_binary_files() {
    fails("", 1, "expected at least one object ([[objects]]), found none");
    fails("# a comment\n\nbackground = [0, 0, 0]\n", 4, "found none");
    let dir = Scratch::new("native-binary");
    let path = dir.write("garbage.toml", [0x00, 0x9f, 0x92, 0x96, b'\n', 0xff]);
    let e = scene::load(&path).unwrap_err();
    assert_eq!(e.line, Some(1), "{e}");
    assert!(
        e.to_string()
            .contains("expected UTF-8 text (TOML), found binary data"),
        "{e}"
    );
}

#[test]
fn bad_geometry() {
    let obj = |body: &str| format!("{SPHERE}\n[[objects]]\n{body}\n");
    fails(
        &obj("type = \"polygon\"\nvertices = [[0, 0, 0], [1, 0, 0]]"),
        6,
        "at least 3 vertices, found 2",
    );
    fails(
        &obj("type = \"polygon\"\nvertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]]"),
        6,
        "collinear",
    );
    fails(
        &obj("type = \"triangle\"\nvertices = [[0, 0, 0], [1, 1, 1], [2, 2, 2]]"),
        6,
        "non-zero area",
    );
    fails(
        &obj("type = \"cone\"\nbase = [0, 0, 0]\nbase_radius = 1\napex = [0, 0, 0]\napex_radius = 1"),
        6,
        "distinct base and apex",
    );
    fails(
        &obj("type = \"sphere\"\ncenter = [0, 0, 0]\nradius = -1"),
        9,
        "a radius > 0, found -1",
    );
    fails(
        &obj("type = \"plane\"\nimplicit = [0, 0, 0, 1]"),
        6,
        "non-zero normal",
    );
    fails(
        &obj("type = \"plane\"\nimplicit = [0, 1, 0, 1]\npoint = [0, 0, 0]"),
        6,
        "exactly one plane form",
    );
    fails(
        &obj("type = \"plane\"\norigin = [0, 0, 0]\ni = [1, 0, 0]"),
        6,
        "exactly one plane form",
    );
    fails(
        &obj("type = \"plane\"\nimplicit = [0, 1, 0]"),
        8,
        "expected an array of length 4, found length 3",
    );
}

#[test]
fn bad_transforms_materials_and_cameras() {
    let with =
        |extra: &str| format!("[[objects]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n{extra}\n");
    fails(
        &with("transform = { scale = [1, 0, 1] }"),
        5,
        "invertible transform, found a singular one",
    );
    fails(
        &with("transform = { rotate = { axis = [0, 0, 0], degrees = 5 } }"),
        5,
        "non-zero rotation axis",
    );
    fails(
        &with("transform = { matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]] }"),
        5,
        "affine",
    );
    fails(
        &with("transform = { matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], scale = 2 }"),
        5,
        "either `matrix` or",
    );
    fails(&with("transform = { shear = 2 }"), 5, "unknown field `shear`");
    fails(
        &with("transform = { scale = \"big\" }"),
        5,
        "expected a number or an array of 3 numbers",
    );
    fails(
        &with("material = \"gold\""),
        5,
        "a material defined under [materials], found `gold`",
    );
    fails(
        &format!(
            "[camera]\neye = [0, 0, 5]\ncenter = [0, 0, 5]\nfovx = 60\nfovy = 60\nwidth = 8\nheight = 8\n\n{SPHERE}"
        ),
        1,
        "eye and look-at point coincide",
    );
    fails(
        &format!(
            "[camera]\neye = [0, 0, 5]\ncenter = [0, 0, 0]\nfovx = 190\nfovy = 60\nwidth = 8\nheight = 8\n\n{SPHERE}"
        ),
        1,
        "field of view 190",
    );
    fails(
        &format!(
            "[camera]\neye = [0, 0, 5]\ncenter = [0, 0, 0]\nfovx = 60\nfovy = 60\nwidth = -8\nheight = 8\n\n{SPHERE}"
        ),
        6,
        "",
    );
    fails(
        &format!("[materials.red]\ncolor = [1, 0, 0]\nshiny = 3\n{SPHERE}"),
        3,
        "unknown field `shiny`",
    );
}

#[test]
fn include_errors_name_the_right_file_and_line() {
    let dir = Scratch::new("native-include-errors");
    dir.write("broken.nff", "s 0 0 0 1\np 2\n");
    dir.write(
        "self.toml",
        "\n[[objects]]\ntype = \"include\"\npath = \"self.toml\"\n",
    );
    dir.write("a.toml", "[[objects]]\ntype = \"include\"\npath = \"b.toml\"\n");
    dir.write("b.toml", "[[objects]]\ntype = \"include\"\npath = \"a.toml\"\n");
    let include = |path: &str| {
        dir.write(
            "main.toml",
            format!("{SPHERE}\n[[objects]]\ntype = \"include\"\npath = \"{path}\"\n"),
        )
    };

    // An error inside the included file names that file and line, and the include.
    let main = include("broken.nff");
    let e = scene::load(&main).unwrap_err();
    assert_eq!(e.path, dir.path().join("broken.nff"));
    assert_eq!(e.line, Some(2));
    assert!(
        e.message
            .ends_with(&format!("(included from {}:8)", main.display())),
        "{e}"
    );
    // A file that cannot be read: the include line of the including file.
    let main = include("missing.nff");
    let e = scene::load(&main).unwrap_err();
    assert_eq!((e.path.clone(), e.line), (main.clone(), Some(8)), "{e}");
    assert!(
        e.message
            .contains("expected a readable scene file at `missing.nff`"),
        "{e}"
    );
    let main = include("notes.txt");
    let e = scene::load(&main).unwrap_err();
    assert!(e.message.contains("unknown scene format"), "{e}");
    // Cycles, direct and indirect.
    let e = scene::load(&dir.path().join("self.toml")).unwrap_err();
    assert_eq!(e.line, Some(4), "{e}");
    assert!(e.message.contains("found a cycle through `self.toml`"), "{e}");
    let e = scene::load(&dir.path().join("a.toml")).unwrap_err();
    assert!(e.message.contains("found a cycle through `a.toml`"), "{e}");
}
