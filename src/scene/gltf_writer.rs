//! Writing a scene as glTF 2.0 (`.glb`, or `.gltf` with its buffer in a
//! `data:` URI): the converse of [`gltf`](crate::scene::gltf)'s reader, so
//! that an instanced scene made here (`raypack gen forest`) is a file other
//! tools open and raypack reads back as the same instances.
//!
//! What is written, and how the reader takes it back:
//!
//! - **Meshes**: each instanced [`Mesh`](crate::scene::Mesh) becomes a glTF mesh, and the scene's
//!   own primitives one more, placed once by an identity node that comes
//!   first, so every primitive reads back under its id. A mesh's triangles
//!   are split into glTF primitives at each change of material or of smooth
//!   shading (a primitive has a NORMAL attribute for all of its vertices or
//!   none), in order; vertices shared by a primitive's triangles are written
//!   once (u32 indices). Only triangles can be written (and polygons of three
//!   vertices, NFF's `p 3`, as the triangles they are): a sphere, plane,
//!   larger polygon, cone or transformed primitive is refused, naming it.
//! - **Instances**: one node each, its `matrix` the instance's M (exact: a
//!   32-bit float is written as the 64-bit number it equals).
//! - **Materials**: `baseColorFactor` = colour; roughness = √(2 / Phong
//!   exponent) in [0.05, 1] and metallic = ks / (1 − roughness), the inverse
//!   of the reader's mapping; transmittance as `KHR_materials_transmission`.
//!   The reader's `kd` is 1 − ks and its index of refraction 1.5: a material
//!   with another `kd` or `ior` reads back with those.
//! - **Lights** as `KHR_lights_punctual` point lights; **the camera** as a
//!   perspective camera on a node looking down its −z (`yfov` = the vertical
//!   field of view, `aspectRatio` from both). glTF has no background colour
//!   and no image size: the reader's defaults apply.

use std::collections::HashMap;
use std::io::{self, Write};

use base64::Engine as _;
use glam::{Mat4, Vec3, Vec4};
use serde_json::{Value, json};

use crate::geometry::Primitive;
use crate::scene::model::{CameraSpec, Material, Scene};

/// The container a glTF document is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Container {
    /// Binary glTF (`.glb`): the JSON and the buffer in one file.
    Glb,
    /// JSON (`.gltf`) with the buffer as a base64 `data:` URI.
    Json,
}

impl Container {
    /// The container a file name asks for, by its extension (`.glb` or
    /// `.gltf`, any case); None for another.
    pub fn of_path(path: &std::path::Path) -> Option<Container> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "glb" => Some(Container::Glb),
            "gltf" => Some(Container::Json),
            _ => None,
        }
    }
}

/// Why a scene cannot be written as glTF.
#[derive(Debug, thiserror::Error)]
pub enum GltfWriteError {
    /// A primitive glTF has no shape for (a polygon is not split: its
    /// pieces would each take an id of their own).
    #[error("glTF holds triangle meshes: {at} is a {kind} (write NFF or TOML instead)")]
    NotATriangle {
        /// Which primitive (the scene's own by index, or a mesh's).
        at: String,
        /// Its kind, in lower case.
        kind: String,
    },
    /// Writing failed.
    #[error(transparent)]
    Io(#[from] io::Error),
}

/// glTF's component type of 32-bit floats (`accessor.componentType`).
const FLOAT: u32 = 5126;
/// glTF's component type of 32-bit unsigned integers.
const UNSIGNED_INT: u32 = 5125;
/// `bufferView.target` of vertex attributes.
const ARRAY_BUFFER: u32 = 34962;
/// `bufferView.target` of indices.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Write `scene` to `out` as glTF in `container`; returns `out` for the caller
/// to finish.
pub fn write_gltf<W: Write>(scene: &Scene, container: Container, mut out: W) -> Result<W, GltfWriteError> {
    let mut doc = Document::default();
    // The scene's own primitives first (ids 0..n), then each instanced mesh.
    let own = doc.mesh(
        "scene",
        &scene.primitives,
        &scene.material_of,
        &scene.vertex_normals,
        &|i| format!("primitive {i}"),
    )?;
    let mut meshes = Vec::with_capacity(scene.instances.meshes().len());
    for mesh in scene.instances.meshes() {
        meshes.push(doc.mesh(
            &mesh.name,
            &mesh.primitives,
            &mesh.material_of,
            &mesh.vertex_normals,
            &|i| format!("primitive {i} of mesh `{}`", mesh.name),
        )?);
    }
    let mut nodes = Vec::new();
    if let Some(own) = own {
        nodes.push(json!({ "mesh": own }));
    }
    // An instance of an empty mesh (no ids) has nothing to place.
    for instance in scene.instances.list() {
        if let Some(mesh) = meshes[instance.mesh as usize] {
            nodes.push(json!({ "mesh": mesh, "matrix": matrix(instance.to_world) }));
        }
    }
    let mut extensions_used = Vec::new();
    let mut cameras = Vec::new();
    if let Some(spec) = &scene.camera {
        cameras.push(camera(spec));
        nodes.push(json!({ "camera": 0, "matrix": matrix(camera_to_world(spec)) }));
    }
    let mut lights = Vec::new();
    for (k, light) in scene.lights.iter().enumerate() {
        lights.push(json!({ "type": "point", "color": light.color.to_array() }));
        nodes.push(json!({
            "translation": light.position.to_array(),
            "extensions": { "KHR_lights_punctual": { "light": k } },
        }));
    }
    let materials: Vec<Value> = scene.materials.iter().map(material).collect();
    if !lights.is_empty() {
        extensions_used.push("KHR_lights_punctual");
    }
    if scene.materials.iter().any(|m| m.transmittance > 0.0) {
        extensions_used.push("KHR_materials_transmission");
    }

    // Assemble the document, its buffer last (its length is known now).
    let bin = std::mem::take(&mut doc.bin);
    let mut buffer = json!({ "byteLength": bin.len() });
    if container == Container::Json {
        let data = base64::engine::general_purpose::STANDARD.encode(&bin);
        buffer["uri"] = format!("data:application/octet-stream;base64,{data}").into();
    }
    let mut root = json!({
        "asset": { "version": "2.0", "generator": format!("raypack {}", env!("CARGO_PKG_VERSION")) },
        "scene": 0,
        "scenes": [{ "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": doc.meshes,
        "accessors": doc.accessors,
        "bufferViews": doc.views,
        "buffers": [buffer],
    });
    if !materials.is_empty() {
        root["materials"] = materials.into();
    }
    if !cameras.is_empty() {
        root["cameras"] = cameras.into();
    }
    if !lights.is_empty() {
        root["extensions"] = json!({ "KHR_lights_punctual": { "lights": lights } });
    }
    if !extensions_used.is_empty() {
        root["extensionsUsed"] = extensions_used.into();
    }
    let text = serde_json::to_vec(&root).map_err(io::Error::other)?;
    match container {
        Container::Json => out.write_all(&text)?,
        Container::Glb => write_glb(&text, &bin, &mut out)?,
    }
    out.flush()?;
    Ok(out)
}

/// The GLB container (glTF 2.0 specification, section 4.4): a 12-byte header,
/// then the JSON chunk (padded with spaces) and the binary chunk (padded with
/// zeros), each to a multiple of 4 bytes.
fn write_glb(json: &[u8], bin: &[u8], out: &mut impl Write) -> io::Result<()> {
    let padded = |n: usize| n.next_multiple_of(4);
    let length = 12 + 8 + padded(json.len()) + 8 + padded(bin.len());
    let length = u32::try_from(length).map_err(|_| io::Error::other("a GLB holds at most 4 GiB"))?;
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&length.to_le_bytes())?;
    for (chunk, kind, pad) in [(json, b"JSON", b' '), (bin, b"BIN\0", 0)] {
        let padding = padded(chunk.len()) - chunk.len();
        out.write_all(&((chunk.len() + padding) as u32).to_le_bytes())?;
        out.write_all(kind)?;
        out.write_all(chunk)?;
        out.write_all(&vec![pad; padding])?;
    }
    Ok(())
}

/// The parts of the document that the meshes fill in.
#[derive(Default)]
struct Document {
    /// The binary buffer: every view 4-byte aligned.
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Vec<Value>,
}

/// The vertices of one glTF primitive, each written once, and its triangles.
#[derive(Default)]
struct Run {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    indices: Vec<u32>,
    /// Each vertex's index, by the bits of its position and normal.
    index_of: HashMap<[u32; 6], u32>,
}

impl Run {
    /// Add a triangle of `corners` with shading `normals` (or none).
    fn push(&mut self, corners: [Vec3; 3], normals: Option<&[Vec3; 3]>) {
        for k in 0..3 {
            let (p, n) = (corners[k], normals.map_or(Vec3::ZERO, |n| n[k]));
            let key = [p.x, p.y, p.z, n.x, n.y, n.z].map(f32::to_bits);
            let next = self.positions.len() as u32;
            let index = *self.index_of.entry(key).or_insert(next);
            if index == next {
                self.positions.push(p);
                if normals.is_some() {
                    self.normals.push(n);
                }
            }
            self.indices.push(index);
        }
    }
}

impl Document {
    /// Add a mesh of triangles `prims` (`at(i)` names primitive `i` in an
    /// error); returns its index, None for no triangles (glTF's meshes have
    /// at least one primitive).
    fn mesh(
        &mut self,
        name: &str,
        prims: &[Primitive],
        material_of: &[u32],
        vertex_normals: &HashMap<u32, [Vec3; 3]>,
        at: &dyn Fn(usize) -> String,
    ) -> Result<Option<usize>, GltfWriteError> {
        let mut primitives = Vec::new();
        let mut run = Run::default();
        // The key of the run being filled: material and smooth shading.
        let mut key = None;
        for (i, prim) in prims.iter().enumerate() {
            let corners = match prim {
                Primitive::Triangle(triangle) => triangle.vertices(),
                // NFF's `p` with three vertices (how the generators write
                // triangles) is the triangle it bounds.
                Primitive::Polygon(polygon) if polygon.vertices().len() == 3 => {
                    let v = polygon.vertices();
                    [v[0], v[1], v[2]]
                }
                Primitive::Polygon(polygon) => {
                    return Err(GltfWriteError::NotATriangle {
                        at: at(i),
                        kind: format!("polygon of {} vertices", polygon.vertices().len()),
                    });
                }
                _ => {
                    return Err(GltfWriteError::NotATriangle {
                        at: at(i),
                        kind: format!("{:?}", prim.kind()).to_lowercase(),
                    });
                }
            };
            let normals = vertex_normals.get(&(i as u32));
            let this = (material_of[i], normals.is_some());
            if let Some((material, _)) = key.filter(|&k| k != this) {
                primitives.push(self.primitive(std::mem::take(&mut run), material));
            }
            key = Some(this);
            run.push(corners, normals);
        }
        let Some((material, _)) = key else {
            return Ok(None);
        };
        primitives.push(self.primitive(run, material));
        self.meshes
            .push(json!({ "name": name, "primitives": primitives }));
        Ok(Some(self.meshes.len() - 1))
    }

    /// A glTF primitive of `run`, of `material`.
    fn primitive(&mut self, run: Run, material: u32) -> Value {
        let position = self.vec3s(&run.positions, true);
        let mut attributes = json!({ "POSITION": position });
        if !run.normals.is_empty() {
            attributes["NORMAL"] = self.vec3s(&run.normals, false).into();
        }
        let bytes = run.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let indices = self.view(bytes, ELEMENT_ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": indices,
            "componentType": UNSIGNED_INT,
            "count": run.indices.len(),
            "type": "SCALAR",
        }));
        json!({
            "attributes": attributes,
            "indices": self.accessors.len() - 1,
            "material": material,
        })
    }

    /// An accessor of `points` (with the min and max the schema asks of
    /// POSITION); returns its index.
    fn vec3s(&mut self, points: &[Vec3], bounds: bool) -> usize {
        let bytes = points
            .iter()
            .flat_map(|p| p.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let view = self.view(bytes, ARRAY_BUFFER);
        let mut accessor = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": points.len(),
            "type": "VEC3",
        });
        if bounds {
            let min = points.iter().copied().fold(Vec3::INFINITY, Vec3::min);
            let max = points.iter().copied().fold(Vec3::NEG_INFINITY, Vec3::max);
            accessor["min"] = min.to_array().into();
            accessor["max"] = max.to_array().into();
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// A buffer view of `bytes` (a multiple of 4 long); returns its index.
    fn view(&mut self, bytes: Vec<u8>, target: u32) -> usize {
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": self.bin.len(),
            "byteLength": bytes.len(),
            "target": target,
        }));
        self.bin.extend_from_slice(&bytes);
        self.views.len() - 1
    }
}

/// A matrix as glTF's column-major array of 16.
fn matrix(m: Mat4) -> [f32; 16] {
    m.to_cols_array()
}

/// The node transform of a camera at `spec`'s eye whose −z looks at its
/// centre and whose +y is its up (made orthogonal to the view).
fn camera_to_world(spec: &CameraSpec) -> Mat4 {
    let forward = (spec.center - spec.eye).normalize();
    let right = forward.cross(spec.up).normalize();
    let up = right.cross(forward);
    Mat4::from_cols(
        right.extend(0.0),
        up.extend(0.0),
        (-forward).extend(0.0),
        spec.eye.extend(1.0),
    )
}

/// glTF's perspective camera of the same fields of view.
fn camera(spec: &CameraSpec) -> Value {
    let half = |degrees: f32| (0.5 * degrees.to_radians()).tan();
    json!({
        "type": "perspective",
        "perspective": {
            "yfov": spec.fovy.to_radians(),
            "aspectRatio": half(spec.fovx) / half(spec.fovy),
            "znear": 1e-3,
        },
    })
}

/// glTF's metallic–roughness material for `m` (see the module documentation).
fn material(m: &Material) -> Value {
    let roughness = if m.shine > 0.0 {
        (2.0 / m.shine).sqrt().clamp(0.05, 1.0)
    } else {
        1.0
    };
    let metallic = if roughness < 1.0 {
        (m.ks / (1.0 - roughness)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let color = Vec4::from((m.color.clamp(Vec3::ZERO, Vec3::ONE), 1.0));
    let mut out = json!({
        "pbrMetallicRoughness": {
            "baseColorFactor": color.to_array(),
            "metallicFactor": metallic,
            "roughnessFactor": roughness,
        },
    });
    if m.transmittance > 0.0 {
        out["extensions"] = json!({
            "KHR_materials_transmission": { "transmissionFactor": m.transmittance.clamp(0.0, 1.0) }
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn materials_map_back_to_what_the_reader_makes() {
        // A polished metal: ks 0.8 at an exponent of 200 (roughness 0.1).
        let m = Material {
            ks: 0.8,
            kd: 0.2,
            shine: 200.0,
            ..Material::default()
        };
        let v = material(&m);
        let pbr = &v["pbrMetallicRoughness"];
        let roughness = pbr["roughnessFactor"].as_f64().unwrap() as f32;
        let metallic = pbr["metallicFactor"].as_f64().unwrap() as f32;
        assert!((roughness - 0.1).abs() < 1e-6, "{roughness}");
        // The reader's ks = metallic · (1 − roughness), shine = 2 / roughness².
        assert!((metallic * (1.0 - roughness) - 0.8).abs() < 1e-6);
        assert!((2.0 / (roughness * roughness) - 200.0).abs() < 1e-2);
        // A diffuse material is rough and not metallic.
        let diffuse = material(&Material::default());
        assert_eq!(diffuse["pbrMetallicRoughness"]["metallicFactor"], 0.0);
        assert_eq!(diffuse["pbrMetallicRoughness"]["roughnessFactor"], 1.0);
    }

    #[test]
    fn glb_chunks_are_padded_to_four_bytes() {
        let mut out = Vec::new();
        write_glb(b"{}", &[1, 2, 3, 4, 5], &mut out).unwrap();
        assert_eq!(&out[..4], b"glTF");
        assert_eq!(
            u32::from_le_bytes(out[8..12].try_into().unwrap()) as usize,
            out.len()
        );
        assert_eq!(out.len(), 12 + 8 + 4 + 8 + 8);
        assert_eq!(&out[20..24], b"{}  ");
        assert_eq!(&out[32..40], &[1, 2, 3, 4, 5, 0, 0, 0]);
    }
}
