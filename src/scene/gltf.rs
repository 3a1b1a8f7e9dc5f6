//! glTF 2.0: `.gltf` (JSON, its buffers in files beside it or in `data:`
//! URIs) and `.glb` (binary), read with the `gltf` crate, which checks the
//! document against the schema.
//!
//! What raypack takes, and how:
//!
//! - **Meshes** become instanced [`Mesh`]es, one per glTF mesh: the triangles
//!   of its primitives (mode TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN;
//!   indexed by u8, u16 or u32, or not indexed; normalized and sparse
//!   accessors as the crate reads them), each with its primitive's material,
//!   and the NORMAL attribute as smooth shading normals. Points and lines are
//!   counted and left out ([`Scene::notes`] says so).
//! - **Nodes** of the default scene (else the first): each node with a mesh
//!   places it by the product of the transforms from the root (matrix, or
//!   translation · rotation · scale). A node with a singular transform (a
//!   scale of 0, which exporters use to hide) places nothing, noted.
//! - **The first perspective camera** met in the node tree: its node's
//!   position, −z as the view direction, +y as up, `yfov` and the aspect ratio
//!   (1 without one) at 512 pixels wide. Without one, raypack frames the scene.
//! - **Materials**, metallic–roughness to raypack's Phong/Whitted
//!   [`Material`]: colour = `baseColorFactor` (rgb); specular weight `ks` =
//!   metallic · (1 − roughness) (a polished metal is a mirror, a rough one
//!   diffuse); `kd` = 1 − `ks`; Phong exponent = 2 / max(roughness, 0.05)²;
//!   `KHR_materials_transmission`'s factor as the transmittance, with glTF's
//!   index of refraction 1.5. Textures are not read.
//! - **Lights** of `KHR_lights_punctual`: point and spot lights as raypack's
//!   positional lights (a spot's cone is not modelled), their colour; a
//!   directional light is noted and left out.
//!
//! Errors name the file and the JSON path (`meshes[0].primitives[1].indices`)
//! or the accessor; nothing panics on a malformed file.

use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::{Mode, Semantic};
use glam::{Mat4, Vec3};

use crate::geometry::{Primitive, Triangle};
use crate::scene::error::SceneError;
use crate::scene::instance::{InstanceError, Mesh};
use crate::scene::model::{CameraSpec, Light, Material, Scene};

/// Deepest node tree followed (a longer chain is refused as malformed).
pub const MAX_NODE_DEPTH: usize = 256;

/// The extensions raypack reads (others are noted, or refused where required).
const SUPPORTED: [&str; 2] = ["KHR_lights_punctual", "KHR_materials_transmission"];

/// Read the glTF or GLB file at `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let bytes = std::fs::read(path).map_err(|e| SceneError::file(path, format!("cannot read: {e}")))?;
    parse(path, &bytes)
}

/// Parse glTF or GLB bytes; `path` names the file in errors and locates
/// external buffers.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<Scene, SceneError> {
    let fail = |message: String| SceneError::file(path, message);
    // A GLB header whose total length is below the header's own 12 bytes
    // underflows inside the gltf crate (1.4.1): refused here first.
    if let Some(length) = glb_length(bytes)
        && length < 12
    {
        return Err(fail(format!(
            "expected a GLB length of at least its 12-byte header, found {length}"
        )));
    }
    // gltf-json 1.4.1's validation reads a POSITION accessor without a bounds
    // check (mesh.rs:151): such an index is refused here first.
    if let Ok(unchecked) = ::gltf::Gltf::from_slice_without_validation(bytes) {
        position_accessors_exist(unchecked.document.as_json()).map_err(fail)?;
    }
    let gltf = ::gltf::Gltf::from_slice(bytes)
        .map_err(|e| fail(format!("expected a valid glTF 2.0 file, found: {e}")))?;
    let document = &gltf.document;
    let mut notes = Vec::new();
    for extension in document.extensions_required() {
        if !SUPPORTED.contains(&extension) {
            return Err(fail(format!(
                "expected required extensions among {}, found `{extension}`",
                SUPPORTED.join(", ")
            )));
        }
    }
    for extension in document.extensions_used() {
        if !SUPPORTED.contains(&extension) {
            notes.push(format!("extension `{extension}` not supported: ignored"));
        }
    }
    let buffers = buffers(path, document, gltf.blob.as_deref()).map_err(fail)?;
    let mut scene = Scene {
        source: path.display().to_string(),
        ..Scene::default()
    };
    scene.materials = document.materials().map(|m| material(&m)).collect();
    let default_material = scene.materials.len() as u32;
    scene.materials.push(Material::default());

    // One mesh per glTF mesh that has triangles.
    let (mut points, mut lines) = (0, 0);
    let mut mesh_of = vec![None; document.meshes().len()];
    for mesh in document.meshes() {
        let mut out = Mesh {
            name: mesh
                .name()
                .map_or_else(|| format!("meshes[{}]", mesh.index()), str::to_string),
            ..Mesh::default()
        };
        for primitive in mesh.primitives() {
            let at = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
            match primitive.mode() {
                Mode::Points => points += 1,
                Mode::Lines | Mode::LineLoop | Mode::LineStrip => lines += 1,
                mode => {
                    let material = primitive
                        .material()
                        .index()
                        .map_or(default_material, |i| i as u32);
                    triangles(&primitive, mode, &buffers, material, &mut out)
                        .map_err(|e| fail(format!("{at}{e}")))?;
                }
            }
        }
        if !out.primitives.is_empty() {
            mesh_of[mesh.index()] = Some(scene.add_mesh(out));
        }
    }
    let left_out = format!("{points} point and {lines} line primitives left out (raypack traces surfaces)");
    if points + lines > 0 {
        notes.push(left_out.clone());
    }

    // The node tree: instances, the camera, the lights.
    let roots: Vec<::gltf::Node> = match document.default_scene().or_else(|| document.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => Vec::new(),
    };
    let mut walk = Walk {
        mesh_of: &mesh_of,
        scene: &mut scene,
        notes: &mut notes,
        camera: None,
        hidden: 0,
        on_path: Vec::new(),
    };
    for root in roots {
        walk.node(&root, Mat4::IDENTITY).map_err(fail)?;
    }
    let (camera, hidden) = (walk.camera, walk.hidden);
    if hidden > 0 {
        notes.push(format!(
            "{hidden} mesh nodes with a singular transform (scale 0) place nothing"
        ));
    }
    if document.scenes().len() == 0 {
        // No scene to say where meshes go: each once, where it is.
        for mesh in mesh_of.iter().flatten() {
            scene
                .place(*mesh, Mat4::IDENTITY)
                .map_err(|e| fail(e.to_string()))?;
        }
    }
    if scene.id_count() == 0 {
        return Err(fail(format!(
            "expected at least one triangle in the scene, found none ({left_out})"
        )));
    }
    scene.camera = camera;
    scene.notes = notes;
    Ok(scene)
}

/// The node tree's walk: what it adds to the scene.
struct Walk<'a> {
    mesh_of: &'a [Option<u32>],
    scene: &'a mut Scene,
    notes: &'a mut Vec<String>,
    camera: Option<CameraSpec>,
    hidden: usize,
    /// The nodes from the root to the current one (a node among its own
    /// ancestors makes the graph a cycle).
    on_path: Vec<usize>,
}

impl Walk<'_> {
    /// Node `node` under the parent transform `parent`, then its children.
    fn node(&mut self, node: &::gltf::Node, parent: Mat4) -> Result<(), String> {
        let at = format!("nodes[{}]", node.index());
        if self.on_path.contains(&node.index()) {
            return Err(format!(
                "{at}: expected a tree of nodes, found the node among its own descendants"
            ));
        }
        if self.on_path.len() >= MAX_NODE_DEPTH {
            return Err(format!(
                "{at}: expected nodes nested at most {MAX_NODE_DEPTH} deep"
            ));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            return Err(format!(
                "{at}: expected a finite transform, found NaN or infinity"
            ));
        }
        if let Some(mesh) = node
            .mesh()
            .and_then(|m| self.mesh_of.get(m.index()).copied().flatten())
        {
            match self.scene.place(mesh, world) {
                Ok(_) => {}
                Err(InstanceError::Transform(_)) if world.determinant() == 0.0 => self.hidden += 1,
                Err(e) => return Err(format!("{at}: {e}")),
            }
        }
        if self.camera.is_none()
            && let Some(camera) = node.camera()
        {
            match camera.projection() {
                ::gltf::camera::Projection::Perspective(p) => {
                    self.camera = camera_spec(world, p.yfov(), p.aspect_ratio())
                }
                ::gltf::camera::Projection::Orthographic(_) => {
                    self.notes
                        .push(format!("{at}: orthographic camera not supported: ignored"));
                }
            }
        }
        if let Some(light) = node.light() {
            use ::gltf::khr_lights_punctual::Kind;
            match light.kind() {
                Kind::Point | Kind::Spot { .. } => self.scene.lights.push(Light {
                    position: world.transform_point3(Vec3::ZERO),
                    color: Vec3::from(light.color()),
                }),
                Kind::Directional => self
                    .notes
                    .push(format!("{at}: directional light not supported: ignored")),
            }
        }
        self.on_path.push(node.index());
        for child in node.children() {
            self.node(&child, world)?;
        }
        self.on_path.pop();
        Ok(())
    }
}

/// A camera at `world`'s origin looking down its −z with `yfov` (radians) and
/// `aspect` (width / height); None where they make no usable camera.
fn camera_spec(world: Mat4, yfov: f32, aspect: Option<f32>) -> Option<CameraSpec> {
    let aspect = aspect
        .filter(|a| a.is_finite() && *a > 0.01 && *a < 100.0)
        .unwrap_or(1.0);
    let eye = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
    let fovx = 2.0 * ((0.5 * yfov).tan() * aspect).atan();
    let spec = CameraSpec {
        eye,
        center: eye + forward,
        up,
        fovx: fovx.to_degrees(),
        fovy: yfov.to_degrees(),
        width: 512,
        height: ((512.0 / aspect).round() as u32).clamp(1, 8192),
    };
    spec.camera().is_ok().then_some(spec)
}

/// raypack's material for a glTF material (see the module documentation).
fn material(m: &::gltf::Material) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _] = pbr.base_color_factor();
    let (metallic, roughness) = (
        pbr.metallic_factor().clamp(0.0, 1.0),
        pbr.roughness_factor().clamp(0.0, 1.0),
    );
    let ks = metallic * (1.0 - roughness);
    let transmittance = m
        .transmission()
        .map_or(0.0, |t| t.transmission_factor().clamp(0.0, 1.0));
    Material {
        color: Vec3::new(r, g, b).clamp(Vec3::ZERO, Vec3::ONE),
        kd: 1.0 - ks,
        ks,
        shine: 2.0 / roughness.max(0.05).powi(2),
        transmittance,
        ior: if transmittance > 0.0 { 1.5 } else { 1.0 },
    }
}

/// Append the triangles of `primitive` (drawn as `mode`) to `out`, each of
/// `material`; an error is the JSON path's tail and what was wrong.
fn triangles(
    primitive: &::gltf::Primitive,
    mode: Mode,
    buffers: &[Vec<u8>],
    material: u32,
    out: &mut Mesh,
) -> Result<(), String> {
    let position = primitive
        .get(&Semantic::Positions)
        .ok_or(".attributes: expected a POSITION attribute, found none")?;
    check_type(
        &position,
        &[DataType::F32],
        Dimensions::Vec3,
        ".attributes.POSITION",
    )?;
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let short = |what: &str, index: usize| {
        format!("{what} (accessor {index}): expected its data within its buffer, found the buffer short")
    };
    let positions: Vec<Vec3> = reader
        .read_positions()
        .ok_or_else(|| short(".attributes.POSITION", position.index()))?
        .map(Vec3::from)
        .collect();
    if positions.len() != position.count() {
        return Err(short(".attributes.POSITION", position.index()));
    }
    if let Some(k) = positions.iter().position(|p| !p.is_finite()) {
        return Err(format!(
            ".attributes.POSITION (accessor {}): expected finite positions, found {} at vertex {k}",
            position.index(),
            positions[k]
        ));
    }
    let normals: Option<Vec<Vec3>> = match primitive.get(&Semantic::Normals) {
        Some(n) => {
            check_type(&n, &[DataType::F32], Dimensions::Vec3, ".attributes.NORMAL")?;
            let normals: Vec<Vec3> = reader
                .read_normals()
                .ok_or_else(|| short(".attributes.NORMAL", n.index()))?
                .map(Vec3::from)
                .collect();
            (normals.len() == positions.len() && normals.iter().all(|n| n.is_finite())).then_some(normals)
        }
        None => None,
    };
    let indices: Vec<u32> = match primitive.indices() {
        Some(i) => {
            check_type(
                &i,
                &[DataType::U8, DataType::U16, DataType::U32],
                Dimensions::Scalar,
                ".indices",
            )?;
            let indices: Vec<u32> = reader
                .read_indices()
                .ok_or_else(|| short(".indices", i.index()))?
                .into_u32()
                .collect();
            if indices.len() != i.count() {
                return Err(short(".indices", i.index()));
            }
            if let Some(&bad) = indices.iter().find(|&&k| k as usize >= positions.len()) {
                return Err(format!(
                    ".indices (accessor {}): expected vertex indices below {}, found {bad}",
                    i.index(),
                    positions.len()
                ));
            }
            indices
        }
        None => (0..positions.len() as u32).collect(),
    };
    for [a, b, c] in corners(mode, &indices) {
        let [a, b, c] = [a, b, c].map(|k| k as usize);
        let id = out.primitives.len() as u32;
        out.primitives.push(Primitive::Triangle(Triangle::new(
            positions[a],
            positions[b],
            positions[c],
        )));
        out.material_of.push(material);
        if let Some(n) = &normals {
            out.vertex_normals.insert(id, [n[a], n[b], n[c]]);
        }
    }
    Ok(())
}

/// The vertex indices of each triangle that `indices` draw as `mode`.
fn corners(mode: Mode, indices: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::TriangleStrip => (2..indices.len())
            .map(|k| {
                // Every other triangle of a strip is wound the other way round.
                let (a, b) = if k % 2 == 0 {
                    (k - 2, k - 1)
                } else {
                    (k - 1, k - 2)
                };
                [indices[a], indices[b], indices[k]]
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len())
            .map(|k| [indices[0], indices[k - 1], indices[k]])
            .collect(),
        _ => indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
}

/// `accessor` holds at least one element, its component type is one of
/// `types` and its shape `dimensions`.
fn check_type(
    accessor: &::gltf::Accessor,
    types: &[DataType],
    dimensions: Dimensions,
    what: &str,
) -> Result<(), String> {
    // The schema asks for at least one element (and one sparse element);
    // the gltf crate's reader subtracts 1 from both unchecked.
    let sparse_count = accessor.sparse().map_or(1, |sparse| sparse.count());
    if accessor.count() == 0 || sparse_count == 0 {
        return Err(format!(
            "{what} (accessor {}): expected a count of at least 1, found 0",
            accessor.index()
        ));
    }
    if types.contains(&accessor.data_type()) && accessor.dimensions() == dimensions {
        return Ok(());
    }
    Err(format!(
        "{what} (accessor {}): expected {dimensions:?} of {}, found {:?} of {:?}",
        accessor.index(),
        types
            .iter()
            .map(|t| format!("{t:?}"))
            .collect::<Vec<_>>()
            .join(" or "),
        accessor.dimensions(),
        accessor.data_type()
    ))
}

/// Every buffer's bytes: the GLB's binary chunk, a `data:` URI's base64, or a
/// file beside `path`; each at least as long as it says.
fn buffers(path: &Path, document: &::gltf::Document, blob: Option<&[u8]>) -> Result<Vec<Vec<u8>>, String> {
    document
        .buffers()
        .map(|buffer| {
            let at = format!("buffers[{}]", buffer.index());
            let data = match buffer.source() {
                ::gltf::buffer::Source::Bin => blob
                    .map(<[u8]>::to_vec)
                    .ok_or(format!("{at}: expected the GLB's binary chunk, found none"))?,
                ::gltf::buffer::Source::Uri(uri) => match uri.strip_prefix("data:") {
                    Some(data) => {
                        let (_, base64) = data
                            .split_once(";base64,")
                            .ok_or(format!("{at}: expected a base64 data URI, found another"))?;
                        decode_base64(base64)
                            .ok_or(format!("{at}: expected base64 data, found other characters"))?
                    }
                    None => {
                        let file = path.parent().unwrap_or(Path::new("")).join(percent_decoded(uri));
                        std::fs::read(&file).map_err(|e| format!("{at}: cannot read `{uri}`: {e}"))?
                    }
                },
            };
            if data.len() < buffer.length() {
                return Err(format!(
                    "{at}: expected {} bytes, found {}",
                    buffer.length(),
                    data.len()
                ));
            }
            Ok(data)
        })
        .collect()
}

/// Every primitive's POSITION attribute names an accessor that exists.
fn position_accessors_exist(root: &::gltf::json::Root) -> Result<(), String> {
    let position = ::gltf::json::validation::Checked::Valid(Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(index) = primitive.attributes.get(&position)
                && index.value() >= root.accessors.len()
            {
                return Err(format!(
                    "meshes[{m}].primitives[{p}].attributes.POSITION: expected one of the {} accessors, found {}",
                    root.accessors.len(),
                    index.value()
                ));
            }
        }
    }
    Ok(())
}

/// The total length a GLB header states, if `bytes` start with one.
fn glb_length(bytes: &[u8]) -> Option<u32> {
    let header = bytes.get(..12).filter(|h| h.starts_with(b"glTF"))?;
    Some(u32::from_le_bytes(header[8..12].try_into().ok()?))
}

/// The bytes of standard base64 text (padding optional); None on another character.
fn decode_base64(text: &str) -> Option<Vec<u8>> {
    use base64::Engine as _;
    use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
    const STANDARD_ANY_PADDING: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
    );
    STANDARD_ANY_PADDING.decode(text).ok()
}

/// A URI's `%XX` escapes decoded (glTF URIs name files relative to the document).
fn percent_decoded(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        let hex = bytes
            .get(k + 1..k + 3)
            .and_then(|h| u8::from_str_radix(std::str::from_utf8(h).ok()?, 16).ok());
        match (bytes[k], hex) {
            (b'%', Some(byte)) => {
                out.push(byte);
                k += 3;
            }
            (b, _) => {
                out.push(b);
                k += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_and_percent_escapes_decode() {
        assert_eq!(decode_base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64("aGVsbG8h").unwrap(), b"hello!");
        assert_eq!(decode_base64("").unwrap(), b"");
        assert!(decode_base64("a*b=").is_none());
        assert_eq!(percent_decoded("my%20mesh.bin"), "my mesh.bin");
        assert_eq!(percent_decoded("100%"), "100%");
    }

    #[test]
    fn strips_and_fans_make_triangles() {
        assert_eq!(
            corners(Mode::TriangleStrip, &[0, 1, 2, 3]),
            [[0, 1, 2], [2, 1, 3]]
        );
        assert_eq!(corners(Mode::TriangleFan, &[0, 1, 2, 3]), [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(corners(Mode::Triangles, &[0, 1, 2, 3]), [[0, 1, 2]]);
    }
}
