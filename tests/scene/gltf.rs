//! The glTF reader: files written here (every part of the mapping, and each
//! kind of malformed input, refused with the file and the JSON path), and
//! files from real exporters (Debian's `assimp-testmodels`) against a
//! triangle count made independently from their JSON.

use std::path::Path;

use glam::{Mat4, Vec3};
use raypack::scene::{self, gltf};
use serde_json::{Value, json};

/// Standard base64 with padding.
fn base64(bytes: &[u8]) -> String {
    const DIGITS: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let bits = chunk
            .iter()
            .enumerate()
            .fold(0u32, |acc, (k, &b)| acc | u32::from(b) << (16 - 8 * k));
        for k in 0..4 {
            out.push(if k <= chunk.len() {
                DIGITS[(bits >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    out
}

/// A glTF document: one mesh of two triangles (a unit quad, u16 indices, a
/// red half-metal material) placed by node 0 and its child node 1, a camera
/// on node 2, a point light on node 3; `positions` and `indices` replace the
/// quad's where given.
fn document(positions: &[f32], indices: &[u16]) -> Value {
    let pos: Vec<u8> = positions.iter().flat_map(|x| x.to_le_bytes()).collect();
    let idx: Vec<u8> = indices.iter().flat_map(|x| x.to_le_bytes()).collect();
    let data = [pos.clone(), idx.clone()].concat();
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1, 0.5, 0.25]}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 2, 3]}],
        "nodes": [
            {"mesh": 0, "children": [1], "translation": [0, 0, -3]},
            {"mesh": 0, "translation": [2, 0, 0]},
            {"camera": 0, "translation": [0.5, 0.5, 2]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 5, 0]}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 2.0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1], "metallicFactor": 0.5, "roughnessFactor": 0.5}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": positions.len() / 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": indices.len(), "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": pos.len()},
            {"buffer": 0, "byteOffset": pos.len(), "byteLength": idx.len()}
        ],
        "buffers": [{"byteLength": data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&data))}]
    })
}

const QUAD: [f32; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0];
const QUAD_INDICES: [u16; 6] = [0, 1, 2, 1, 3, 2];

fn parse(doc: &Value) -> Result<scene::Scene, String> {
    gltf::parse(Path::new("test.gltf"), doc.to_string().as_bytes()).map_err(|e| e.to_string())
}

#[test]
fn meshes_nodes_camera_materials_and_lights_are_read() {
    let s = parse(&document(&QUAD, &QUAD_INDICES)).unwrap();
    let summary = s.instancing_summary().unwrap();
    // One mesh of two triangles, placed by node 0 and by its child, node 1.
    assert_eq!(
        (summary.instances, summary.meshes, summary.unique_primitives),
        (2, 1, 2)
    );
    assert_eq!(s.id_count(), 4);
    let placed: Vec<Mat4> = s.instances.list().iter().map(|i| i.to_world).collect();
    assert_eq!(placed[0], Mat4::from_translation(Vec3::new(0.0, 0.0, -3.0)));
    assert_eq!(
        placed[1],
        Mat4::from_translation(Vec3::new(2.0, 0.0, -3.0)),
        "child under parent"
    );
    let camera = s.camera.unwrap();
    assert_eq!(camera.eye, Vec3::new(0.5, 0.5, 2.0));
    assert!((camera.center - Vec3::new(0.5, 0.5, 1.0)).length() < 1e-6);
    assert_eq!((camera.width, camera.height), (512, 256));
    assert!((camera.fovy - 0.8f32.to_degrees()).abs() < 1e-4);
    let m = s.material(2);
    assert_eq!(m.color, Vec3::X);
    assert!((m.ks - 0.25).abs() < 1e-6 && (m.kd - 0.75).abs() < 1e-6);
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.lights[0].position, Vec3::new(0.0, 5.0, 0.0));
    assert_eq!(s.lights[0].color, Vec3::new(1.0, 0.5, 0.25));
    // The same document as GLB gives the same scene.
    let glb = to_glb(&document(&QUAD, &QUAD_INDICES));
    let b = gltf::parse(Path::new("test.glb"), &glb).unwrap();
    assert_eq!(
        b.flattened().unwrap().primitives,
        s.flattened().unwrap().primitives
    );
}

/// A scene written by raypack's glTF writer reads back as itself: each
/// primitive under its id with its vertices, material and shading normals
/// (split into glTF primitives where the material or the smoothness
/// changes), the lights, the materials' mapping both ways; in either container.
#[test]
fn written_scenes_read_back_as_themselves() {
    use raypack::geometry::{Primitive, Sphere, Triangle};
    use raypack::scene::gltf_writer::{Container, write_gltf};
    use raypack::scene::{Light, Material, Mesh};
    let triangle = |k: f32| {
        Primitive::Triangle(Triangle::new(
            Vec3::new(k, 0.0, 0.0),
            Vec3::new(k + 1.0, 0.0, 0.0),
            Vec3::new(k, 1.0, 0.5),
        ))
    };
    let glass = Material {
        color: Vec3::new(0.9, 0.95, 1.0),
        kd: 1.0,
        ks: 0.0,
        transmittance: 0.75,
        ior: 1.5,
        shine: 2.0,
    };
    let mut s = scene::Scene {
        // Materials glTF's mapping takes both ways: kd = 1 − ks, ior 1.5 when
        // transmissive, Phong exponent 2 for a rough surface.
        materials: vec![
            Material {
                shine: 2.0,
                ..Material::default()
            },
            glass,
        ],
        lights: vec![Light {
            position: Vec3::new(1.0, 2.0, 3.0),
            color: Vec3::new(1.0, 0.5, 0.25),
        }],
        ..scene::Scene::default()
    };
    s.push(triangle(-5.0), 1);
    let normals = [Vec3::Z, Vec3::Y, Vec3::X];
    let mut mesh = Mesh {
        name: "parts".into(),
        ..Mesh::default()
    };
    // Materials 0, 0, 1, 0 and smooth shading on the second: four runs.
    for (k, material) in [0, 0, 1, 0].into_iter().enumerate() {
        mesh.primitives.push(triangle(k as f32));
        mesh.material_of.push(material);
    }
    mesh.vertex_normals.insert(1, normals);
    let m = s.add_mesh(mesh);
    s.place(m, Mat4::from_translation(Vec3::new(0.0, 0.0, -3.0)))
        .unwrap();
    s.place(m, Mat4::from_scale(Vec3::new(2.0, 1.0, 0.5))).unwrap();
    for container in [Container::Glb, Container::Json] {
        let bytes = write_gltf(&s, container, Vec::new()).unwrap();
        let read = gltf::parse(Path::new("written.glb"), &bytes).unwrap();
        assert_eq!(read.id_count(), s.id_count());
        let (flat, read_flat) = (s.flattened().unwrap(), read.flattened().unwrap());
        assert_eq!(read_flat.primitives, flat.primitives, "{container:?}");
        assert_eq!(read_flat.material_of, flat.material_of);
        assert_eq!(read_flat.vertex_normals, flat.vertex_normals);
        assert_eq!(read.lights, s.lights);
        assert_eq!(read.materials[..2], s.materials[..], "{container:?}");
        let json: Value = match container {
            Container::Json => serde_json::from_slice(&bytes).unwrap(),
            Container::Glb => {
                let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
                serde_json::from_slice(&bytes[20..20 + length]).unwrap()
            }
        };
        let runs: Vec<usize> = json["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["primitives"].as_array().unwrap().len())
            .collect();
        assert_eq!(runs, [1, 4], "the scene's own triangle, then the mesh's runs");
    }
    // A sphere has no glTF shape: refused, naming it.
    s.push(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)), 0);
    let e = write_gltf(&s, Container::Glb, Vec::new())
        .unwrap_err()
        .to_string();
    assert!(e.contains("primitive 1 is a sphere"), "{e}");
}

/// `doc` as GLB: its buffer moved into the binary chunk.
fn to_glb(doc: &Value) -> Vec<u8> {
    let mut doc = doc.clone();
    let uri = doc["buffers"][0]["uri"].take();
    let data = decode(uri.as_str().unwrap().split_once(',').unwrap().1);
    doc["buffers"][0] = json!({"byteLength": data.len()});
    let mut text = doc.to_string().into_bytes();
    text.resize(text.len().next_multiple_of(4), b' ');
    let mut bin = data;
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::new();
    for word in [0x4654_6C67, 2, total as u32, text.len() as u32, 0x4E4F_534A] {
        out.extend_from_slice(&u32::to_le_bytes(word));
    }
    out.extend_from_slice(&text);
    out.extend_from_slice(&u32::to_le_bytes(bin.len() as u32));
    out.extend_from_slice(&u32::to_le_bytes(0x004E_4942));
    out.extend_from_slice(&bin);
    out
}

/// The bytes of base64 text (the test's own encoder's output).
fn decode(text: &str) -> Vec<u8> {
    let digit = |c: u8| {
        b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/"
            .iter()
            .position(|&d| d == c)
    };
    let digits: Vec<u32> = text.bytes().filter_map(digit).map(|d| d as u32).collect();
    let mut out = Vec::new();
    for chunk in digits.chunks(4) {
        let bits = chunk
            .iter()
            .enumerate()
            .fold(0, |acc, (k, &d)| acc | d << (18 - 6 * k));
        out.extend_from_slice(&bits.to_be_bytes()[1..chunk.len()]);
    }
    out
}

#[test]
fn malformed_files_are_refused_with_the_json_path() {
    let good = document(&QUAD, &QUAD_INDICES);
    let mut cases: Vec<(Value, &str)> = Vec::new();
    // An index past the vertices.
    cases.push((
        document(&QUAD, &[0, 1, 7]),
        "meshes[0].primitives[0].indices (accessor 1): expected vertex indices below 4, found 7",
    ));
    // A buffer shorter than it says.
    let mut short = good.clone();
    short["buffers"][0]["byteLength"] = json!(400);
    cases.push((short, "buffers[0]: expected 400 bytes, found"));
    // A node among its own descendants.
    let mut cycle = good.clone();
    cycle["nodes"][1]["children"] = json!([0]);
    cases.push((
        cycle,
        "expected a tree of nodes, found the node among its own descendants",
    ));
    // A position that is not finite.
    let mut nan = QUAD;
    nan[4] = f32::NAN;
    cases.push((
        document(&nan, &QUAD_INDICES),
        ".attributes.POSITION (accessor 0): expected finite positions, found",
    ));
    // Positions of the wrong component type.
    let mut wrong = good.clone();
    wrong["accessors"][0]["componentType"] = json!(5123);
    cases.push((
        wrong,
        "POSITION (accessor 0): expected Vec3 of F32, found Vec3 of U16",
    ));
    // A schema violation: a mesh without primitives.
    let mut schema = good.clone();
    schema["meshes"][0] = json!({});
    cases.push((schema, "expected a valid glTF 2.0 file, found"));
    // An extension raypack cannot do without.
    let mut required = good.clone();
    required["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    required["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    cases.push((required, "KHR_draco_mesh_compression"));
    // Points only: nothing to trace, and it says why.
    let mut points = good.clone();
    points["meshes"][0]["primitives"][0]["mode"] = json!(0);
    cases.push((points, "found none (1 point and 0 line primitives left out"));
    // A transform that is not finite.
    let mut overflow = good.clone();
    overflow["nodes"][0]["scale"] = json!([1e12, 1e12, 1e12]);
    overflow["nodes"][1]["scale"] = json!([1e30, 1e30, 1e30]);
    cases.push((overflow, "nodes[1]: expected a finite transform"));
    // A transform whose inverse overflows.
    let mut huge = good.clone();
    huge["nodes"][0]["scale"] = json!([3e38, 3e38, 3e38]);
    cases.push((huge, "nodes[0]: transform is singular"));
    for (doc, needle) in cases {
        let e = parse(&doc).expect_err(needle);
        assert!(
            e.starts_with("test.gltf: ") && e.contains(needle),
            "{e}\nwanted: {needle}"
        );
    }
    // A fuzz finding: a GLB header stating a length below its own 12 bytes.
    let e = scene::load(&crate::data("fuzz/gltf_length_below_header.glb")).unwrap_err();
    assert!(
        e.to_string()
            .contains("expected a GLB length of at least its 12-byte header, found 0"),
        "{e}"
    );
    // A fuzz finding: POSITION naming an accessor that does not exist.
    let e = scene::load(&crate::data("fuzz/gltf_position_accessor_missing.gltf")).unwrap_err();
    assert!(
        e.to_string()
            .contains(".attributes.POSITION: expected one of the 0 accessors"),
        "{e}"
    );
    // A fuzz finding: an accessor of no elements (the gltf crate's reader
    // computes its end as offset + stride × (count − 1)).
    let e = scene::load(&crate::data("fuzz/gltf_accessor_count_zero.glb")).unwrap_err();
    assert!(
        e.to_string()
            .contains(".attributes.POSITION (accessor 0): expected a count of at least 1, found 0"),
        "{e}"
    );
    let mut empty = good.clone();
    empty["accessors"][1]["count"] = json!(0);
    let e = parse(&empty).unwrap_err();
    assert!(
        e.contains(".indices (accessor 1): expected a count of at least 1, found 0"),
        "{e}"
    );
    let mut missing = good.clone();
    missing["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(7);
    let e = parse(&missing).unwrap_err();
    assert!(
        e.contains("meshes[0].primitives[0].attributes.POSITION: expected one of the 2 accessors, found 7"),
        "{e}"
    );
    // Not JSON, and a GLB cut short.
    assert!(parse(&json!("nothing")).is_err());
    let glb = to_glb(&good);
    let e = gltf::parse(Path::new("cut.glb"), &glb[..glb.len() - 10]).unwrap_err();
    assert!(e.to_string().starts_with("cut.glb: "), "{e}");
}

#[test]
fn hidden_nodes_and_unknown_extensions_are_noted() {
    let mut doc = document(&QUAD, &QUAD_INDICES);
    doc["nodes"][1]["scale"] = json!([0, 0, 0]);
    doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_texture_transform"]);
    let s = parse(&doc).unwrap();
    assert_eq!(s.instances.list().len(), 1);
    let notes = s.notes.join("\n");
    assert!(
        notes.contains("1 mesh nodes with a singular transform"),
        "{notes}"
    );
    assert!(notes.contains("`KHR_texture_transform` not supported"), "{notes}");
}

/// The triangles a glTF JSON document draws, counted from the JSON alone:
/// each node's mesh once per node of the default scene's trees, each
/// TRIANGLES primitive (the default mode) `count / 3` of its indices (or
/// positions), strips and fans `count − 2`.
fn reference_triangles(doc: &Value) -> u64 {
    let per_mesh: Vec<u64> = doc["meshes"].as_array().map_or(Vec::new(), |meshes| {
        meshes
            .iter()
            .map(|m| {
                m["primitives"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|p| {
                        let accessor = p["indices"]
                            .as_u64()
                            .unwrap_or_else(|| p["attributes"]["POSITION"].as_u64().unwrap());
                        let count = doc["accessors"][accessor as usize]["count"].as_u64().unwrap();
                        match p["mode"].as_u64().unwrap_or(4) {
                            4 => count / 3,
                            5 | 6 => count.saturating_sub(2),
                            _ => 0,
                        }
                    })
                    .sum()
            })
            .collect()
    });
    fn node(doc: &Value, n: u64, per_mesh: &[u64]) -> u64 {
        let node = &doc["nodes"][n as usize];
        let own = node["mesh"].as_u64().map_or(0, |m| per_mesh[m as usize]);
        let children = node["children"]
            .as_array()
            .map_or(0, |c| c.iter().map(|c| node_of(doc, c, per_mesh)).sum());
        own + children
    }
    fn node_of(doc: &Value, n: &Value, per_mesh: &[u64]) -> u64 {
        node(doc, n.as_u64().unwrap(), per_mesh)
    }
    let scene = doc["scene"].as_u64().unwrap_or(0);
    doc["scenes"][scene as usize]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| node_of(doc, n, &per_mesh))
        .sum()
}

/// The JSON of a `.gltf`, or of a `.glb`'s first chunk.
fn json_of(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    if path.extension().is_some_and(|e| e == "glb") {
        let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        return serde_json::from_slice(&bytes[20..20 + length]).unwrap();
    }
    serde_json::from_slice(&bytes).unwrap()
}

#[test]
#[ignore = "needs Debian's assimp-testmodels (installed by .ci/run)"]
fn exporters_files_load_with_the_triangles_their_json_draws() {
    let root = Path::new("/usr/share/assimp/models/glTF2");
    let files = [
        "2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
        "BoxTextured-glTF/BoxTextured.gltf",
        "BoxTextured-glTF-Binary/BoxTextured.glb",
        "BoxTextured-glTF-Embedded/BoxTextured.gltf",
        "ClearCoat-glTF/ClearCoatTest.gltf",
        "textureTransform/TextureTransformTest.gltf",
        "cameras/Cameras.gltf",
        "glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_04.gltf",
        "glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_05.gltf",
        "glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_06.gltf",
    ];
    for file in files {
        let path = root.join(file);
        let s = scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let expected = reference_triangles(&json_of(&path));
        assert!(expected > 0, "{file}");
        assert_eq!(s.id_count(), expected, "{file}");
    }
    // Exporters' malformed files: refused, naming the file.
    for file in [
        "IndexOutOfRange/IndexOutOfRange.gltf",
        "RecursiveNodes/RecursiveNodes.gltf",
        "MissingBin/BoxTextured.gltf",
        "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
        "wrongTypes/badArray.gltf",
    ] {
        let e = scene::load(&root.join(file)).expect_err(file);
        assert!(e.to_string().contains(file), "{e}");
    }
}
