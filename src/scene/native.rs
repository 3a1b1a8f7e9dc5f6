//! The native scene format: TOML, for what NFF cannot say — the lecture's three
//! plane forms, transforms on any object or included file, named materials, and
//! a camera with separate horizontal and vertical fields of view.
//!
//! ```toml
//! background = [0.05, 0.05, 0.08]     # optional, default black
//!
//! [camera]                            # optional
//! eye = [0, 2, 8]
//! center = [0, 1, 0]
//! up = [0, 1, 0]                      # optional, default +y
//! fovx = 60                           # degrees, image edge to edge
//! fovy = 45
//! width = 640
//! height = 480
//!
//! [materials.red]                     # each field optional (NFF's default material)
//! color = [0.8, 0.1, 0.1]
//! kd = 0.7
//! ks = 0.3
//! shine = 40
//! transmittance = 0
//! ior = 1.5
//!
//! [[lights]]
//! position = [4, 6, 4]
//! color = [1, 1, 1]                   # optional, default white
//!
//! [[objects]]                         # one primitive each, numbered in file order
//! type = "sphere"                     # sphere | plane | triangle | polygon | cone | include
//! center = [0, 1, 0]
//! radius = 1
//! inside_only = false                 # optional: NFF's negative radius
//! material = "red"                    # optional: a name under [materials]
//! transform = { scale = [1, 0.5, 1], rotate = { axis = [0, 0, 1], degrees = 30 }, translate = [0, 1, 0] }
//! ```
//!
//! Object fields by type (every object also takes `material` and `transform`):
//!
//! - `sphere`: `center`, `radius`, optional `inside_only`;
//! - `plane`, one of three forms: `implicit = [A, B, C, D]` (`Ax + By + Cz + D = 0`),
//!   `point` + `normal`, or `origin` + `i` + `j` (parametric `origin + u·i + v·j`);
//! - `triangle`: `vertices = [[x, y, z] ×3]`, optional `normals` (×3, smooth shading);
//! - `polygon`: `vertices` (≥ 3, planar, may be concave; the first three fix the normal);
//! - `cone`: `base`, `base_radius`, `apex`, `apex_radius` (no end caps);
//! - `include`: `path` of a scene file (relative to this file; any format
//!   [`scene::load`](crate::scene::load) reads), optional `keep_lights`. Its
//!   primitives take consecutive indices at this point of the file order and
//!   keep their own materials unless `material` is given; its camera and
//!   background are ignored, and so are its lights unless `keep_lights = true`.
//!
//! A `transform` is either `matrix` (4×4, row-major, affine) or any of `scale`
//! (a number or `[sx, sy, sz]`), `rotate` (`{ axis, degrees }`) and `translate`,
//! applied in that order (M = T·R·S). A transformed sphere, cone or plane becomes
//! a [`Transformed`] primitive; triangles and polygons are baked (their vertices
//! transformed), and so are the triangles of an included file.
//!
//! Errors name the file and the line of the offending value.

use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{Mat3, Mat4, Quat, Vec3, Vec4};
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use toml::Spanned;
use toml::de::{DeTable, DeValue, ValueDeserializer};

use crate::geometry::{Cone, GeometryError, Plane, Polygon, Primitive, Sphere, Transformed, Triangle};
use crate::scene::error::{SceneError, geometry_message};
use crate::scene::model::{CameraSpec, Light, Material, Scene};

/// Deepest chain of TOML files including one another that [`load_from`] follows
/// (the top file counts as depth 1). Real scenes nest two or three deep; the
/// cap keeps a long generated chain from exhausting the stack. A constant:
/// raise it here if a scene needs more.
pub const MAX_INCLUDE_DEPTH: usize = 32;

/// Where a TOML scene's includes come from: [`FileSystem`] when a scene is
/// loaded from disk, [`InMemory`] for scenes and their includes held in memory
/// (tests and the fuzz targets, which must never touch the disk).
///
/// [`FileSystem`]: crate::scene::loader::FileSystem
/// [`InMemory`]: crate::scene::loader::InMemory
pub trait SceneFiles {
    /// The name that identifies `path` when looking for include cycles
    /// (two names of one file must give the same identity).
    fn identity(&self, path: &Path) -> PathBuf;
    /// The bytes of the TOML file at `path`; an error without a line when it cannot be read.
    fn read(&self, path: &Path) -> Result<Vec<u8>, SceneError>;
    /// The scene in the non-TOML file at `path` (NFF, OBJ, PLY), read by extension.
    fn load(&self, path: &Path) -> Result<Scene, SceneError>;
}

/// Read the TOML scene at `path`, taking it and its includes from `files`.
pub fn load_from(path: &Path, files: &dyn SceneFiles) -> Result<Scene, SceneError> {
    load_nested(
        path,
        &mut Nesting {
            files,
            stack: Vec::new(),
        },
    )
}

/// Where includes come from, and the TOML files that include the one being read (to refuse cycles).
struct Nesting<'a> {
    files: &'a dyn SceneFiles,
    stack: Vec<PathBuf>,
}

/// Read `path` through `nesting.files`.
fn load_nested(path: &Path, nesting: &mut Nesting) -> Result<Scene, SceneError> {
    let bytes = nesting.files.read(path)?;
    let text = utf8_text(path, &bytes)?;
    nesting.stack.push(nesting.files.identity(path));
    let result = parse_nested(path, text, nesting);
    nesting.stack.pop();
    result
}

/// `bytes` as text, or an error at the line of the first byte that is not UTF-8.
pub fn utf8_text<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str, SceneError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let line = line_of(bytes, e.valid_up_to());
        SceneError::at(path, line, "expected UTF-8 text (TOML), found binary data")
    })
}

/// Parse TOML scene text; `path` names the file in errors and locates
/// includes, read from `files`.
pub fn parse_from(path: &Path, text: &str, files: &dyn SceneFiles) -> Result<Scene, SceneError> {
    parse_nested(
        path,
        text,
        &mut Nesting {
            files,
            stack: Vec::new(),
        },
    )
}

fn parse_nested(path: &Path, text: &str, nesting: &mut Nesting) -> Result<Scene, SceneError> {
    let mut reader = Reader {
        path,
        text,
        scene: Scene {
            source: path.display().to_string(),
            ..Scene::default()
        },
        materials: HashMap::new(),
        default_material: None,
    };
    let mut document = DeTable::parse(text).map_err(|e| reader.toml_error(&e))?;
    let objects = document.get_mut().remove("objects");
    let file: FileToml = reader.deserialize(Spanned::new(
        document.span(),
        DeValue::Table(document.into_inner()),
    ))?;
    reader.header(file)?;
    if let Some(objects) = objects {
        let span = objects.span();
        let DeValue::Array(objects) = objects.into_inner() else {
            return Err(reader.error(
                span,
                "expected `objects` to be an array of tables ([[objects]]), found another value",
            ));
        };
        for object in objects.iter().cloned() {
            reader.object(object, nesting)?;
        }
    }
    if reader.scene.primitives.is_empty() {
        let end = text.len();
        return Err(reader.error(end..end, "expected at least one object ([[objects]]), found none"));
    }
    Ok(reader.scene)
}

/// 1-based line of byte `offset`.
fn line_of(text: &[u8], offset: usize) -> usize {
    1 + text[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// serde's "invalid type: X, expected Y" reworded as "expected Y, found X".
fn reword(message: &str) -> String {
    for prefix in ["invalid type: ", "invalid value: ", "invalid length "] {
        if let Some(rest) = message.strip_prefix(prefix)
            && let Some((found, expected)) = rest.split_once(", expected ")
        {
            let found = if prefix == "invalid length " {
                format!("length {found}")
            } else {
                found.to_string()
            };
            return format!("expected {expected}, found {found}");
        }
    }
    message.to_string()
}

/// A finite number that fits an f32 (TOML also allows nan and inf).
#[derive(Clone, Copy, Debug)]
struct Num(f32);

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let x = f64::deserialize(d)?;
        let f = x as f32;
        if !x.is_finite() {
            return Err(D::Error::custom(format!("expected a finite number, found {x}")));
        }
        if !f.is_finite() {
            return Err(D::Error::custom(format!(
                "expected a number within ±3.4e38, found {x:e}"
            )));
        }
        Ok(Num(f))
    }
}

/// A point, vector or colour: `[x, y, z]` of finite numbers.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(from = "[Num; 3]")]
struct V3(Vec3);

impl From<[Num; 3]> for V3 {
    fn from([x, y, z]: [Num; 3]) -> Self {
        V3(Vec3::new(x.0, y.0, z.0))
    }
}

/// The top-level keys other than `objects`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileToml {
    background: Option<V3>,
    camera: Option<Spanned<CameraToml>>,
    #[serde(default)]
    materials: BTreeMap<String, MaterialToml>,
    #[serde(default)]
    lights: Vec<LightToml>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraToml {
    eye: V3,
    center: V3,
    up: Option<V3>,
    fovx: Num,
    fovy: Num,
    width: u32,
    height: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialToml {
    color: Option<V3>,
    kd: Option<Num>,
    ks: Option<Num>,
    shine: Option<Num>,
    transmittance: Option<Num>,
    ior: Option<Num>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightToml {
    position: V3,
    color: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereToml {
    center: V3,
    radius: Spanned<Num>,
    #[serde(default)]
    inside_only: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PlaneToml {
    implicit: Option<[Num; 4]>,
    point: Option<V3>,
    normal: Option<V3>,
    origin: Option<V3>,
    i: Option<V3>,
    j: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TriangleToml {
    vertices: [V3; 3],
    normals: Option<[V3; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PolygonToml {
    vertices: Vec<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConeToml {
    base: V3,
    base_radius: Num,
    apex: V3,
    apex_radius: Num,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IncludeToml {
    path: Spanned<String>,
    #[serde(default)]
    keep_lights: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransformToml {
    matrix: Option<[[Num; 4]; 4]>,
    scale: Option<ScaleToml>,
    rotate: Option<RotateToml>,
    translate: Option<V3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RotateToml {
    axis: V3,
    degrees: Num,
}

/// `scale = 2` or `scale = [sx, sy, sz]`.
struct ScaleToml(Vec3);

impl<'de> Deserialize<'de> for ScaleToml {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = ScaleToml;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array of 3 numbers")
            }
            fn visit_f64<E: serde::de::Error>(self, x: f64) -> Result<ScaleToml, E> {
                Num::deserialize(serde::de::value::F64Deserializer::<E>::new(x))
                    .map(|s| ScaleToml(Vec3::splat(s.0)))
            }
            fn visit_i64<E: serde::de::Error>(self, x: i64) -> Result<ScaleToml, E> {
                self.visit_f64(x as f64)
            }
            fn visit_u64<E: serde::de::Error>(self, x: u64) -> Result<ScaleToml, E> {
                self.visit_f64(x as f64)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<ScaleToml, A::Error> {
                V3::deserialize(serde::de::value::SeqAccessDeserializer::new(seq)).map(|v| ScaleToml(v.0))
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// The reader's state while it walks the file.
struct Reader<'a> {
    path: &'a Path,
    text: &'a str,
    scene: Scene,
    /// Material index by name.
    materials: HashMap<String, u32>,
    /// Index of the default material, added on first use.
    default_material: Option<u32>,
}

impl Reader<'_> {
    fn error(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError::at(self.path, line_of(self.text.as_bytes(), span.start), message)
    }

    fn toml_error(&self, e: &toml::de::Error) -> SceneError {
        let start = e.span().map_or(0, |s| s.start);
        self.error(start..start, reword(e.message()))
    }

    fn deserialize<'de, T: Deserialize<'de>>(&self, value: Spanned<DeValue<'de>>) -> Result<T, SceneError> {
        T::deserialize(ValueDeserializer::from(value)).map_err(|e| self.toml_error(&e))
    }

    /// Background, camera, materials and lights.
    fn header(&mut self, file: FileToml) -> Result<(), SceneError> {
        if let Some(V3(background)) = file.background {
            self.scene.background = background;
        }
        if let Some(camera) = file.camera {
            let span = camera.span();
            let c = camera.into_inner();
            let spec = CameraSpec {
                eye: c.eye.0,
                center: c.center.0,
                up: c.up.map_or(Vec3::Y, |v| v.0),
                fovx: c.fovx.0,
                fovy: c.fovy.0,
                width: c.width,
                height: c.height,
            };
            spec.camera()
                .map_err(|e| self.error(span, format!("expected a usable camera, found one where {e}")))?;
            self.scene.camera = Some(spec);
        }
        for (name, m) in file.materials {
            let d = Material::default();
            self.scene.materials.push(Material {
                color: m.color.map_or(d.color, |v| v.0),
                kd: m.kd.map_or(d.kd, |x| x.0),
                ks: m.ks.map_or(d.ks, |x| x.0),
                shine: m.shine.map_or(d.shine, |x| x.0),
                transmittance: m.transmittance.map_or(d.transmittance, |x| x.0),
                ior: m.ior.map_or(d.ior, |x| x.0),
            });
            self.materials
                .insert(name, (self.scene.materials.len() - 1) as u32);
        }
        for light in file.lights {
            self.scene.lights.push(Light {
                position: light.position.0,
                color: light.color.map_or(Vec3::ONE, |v| v.0),
            });
        }
        Ok(())
    }

    /// The material index named by an object's `material` key (the default material without one).
    fn material(&mut self, name: Option<Spanned<DeValue>>) -> Result<u32, SceneError> {
        let Some(name) = name else {
            return Ok(*self.default_material.get_or_insert_with(|| {
                self.scene.materials.push(Material::default());
                (self.scene.materials.len() - 1) as u32
            }));
        };
        let span = name.span();
        let name: String = self.deserialize(name)?;
        self.materials.get(&name).copied().ok_or_else(|| {
            self.error(
                span,
                format!("expected the name of a material defined under [materials], found `{name}`"),
            )
        })
    }

    /// One `[[objects]]` entry.
    fn object(&mut self, value: Spanned<DeValue>, nesting: &mut Nesting) -> Result<(), SceneError> {
        let span = value.span();
        let DeValue::Table(mut table) = value.into_inner() else {
            return Err(self.error(span, "expected each object to be a table, found another value"));
        };
        const TYPES: &str = "sphere, plane, triangle, polygon, cone or include";
        let kind = table.remove("type").ok_or_else(|| {
            self.error(
                span.clone(),
                format!("expected a `type` key ({TYPES}), found none"),
            )
        })?;
        let kind_span = kind.span();
        let kind: String = self.deserialize(kind)?;
        let material = table.remove("material");
        let transform = match table.remove("transform") {
            Some(t) => {
                let t_span = t.span();
                let t: TransformToml = self.deserialize(t)?;
                Some(transform_matrix(t).map_err(|message| self.error(t_span, message))?)
            }
            None => None,
        };
        let fields = Spanned::new(span.clone(), DeValue::Table(table));
        let prim = match kind.as_str() {
            "sphere" => {
                let s: SphereToml = self.deserialize(fields)?;
                let radius = s.radius.get_ref().0;
                if radius <= 0.0 {
                    return Err(self.error(s.radius.span(), format!("expected a radius > 0, found {radius}")));
                }
                let sphere = if s.inside_only {
                    Sphere::inside_only(s.center.0, radius)
                } else {
                    Sphere::new(s.center.0, radius)
                };
                placed(Primitive::Sphere(sphere), transform)
            }
            "plane" => {
                let p: PlaneToml = self.deserialize(fields)?;
                let plane = match p {
                    PlaneToml {
                        implicit: Some([a, b, c, d]),
                        point: None,
                        normal: None,
                        origin: None,
                        i: None,
                        j: None,
                    } => Plane::implicit(a.0, b.0, c.0, d.0),
                    PlaneToml {
                        implicit: None,
                        point: Some(q0),
                        normal: Some(n),
                        origin: None,
                        i: None,
                        j: None,
                    } => Plane::point_normal(q0.0, n.0),
                    PlaneToml {
                        implicit: None,
                        point: None,
                        normal: None,
                        origin: Some(q),
                        i: Some(i),
                        j: Some(j),
                    } => Plane::parametric(q.0, i.0, j.0),
                    _ => {
                        return Err(self.error(
                            span,
                            "expected exactly one plane form: `implicit = [A, B, C, D]`, `point` and \
                             `normal`, or `origin`, `i` and `j`, found another combination",
                        ));
                    }
                };
                plane.and_then(|p| placed(Primitive::Plane(p), transform))
            }
            "triangle" => {
                let t: TriangleToml = self.deserialize(fields)?;
                let [a, b, c] = t.vertices.map(|v| bake_point(v.0, transform));
                let triangle = Triangle::new(a, b, c);
                if triangle.is_degenerate() {
                    return Err(self.error(
                        span,
                        "expected a triangle of non-zero area, found a degenerate one",
                    ));
                }
                let material = self.material(material)?;
                let index = self.scene.push(Primitive::Triangle(triangle), material);
                if let Some(normals) = t.normals {
                    let normals = normals.map(|n| bake_normal(n.0, transform));
                    self.scene.vertex_normals.insert(index, normals);
                }
                return Ok(());
            }
            "polygon" => {
                let p: PolygonToml = self.deserialize(fields)?;
                let vertices: Vec<Vec3> = p.vertices.iter().map(|v| bake_point(v.0, transform)).collect();
                Polygon::new(&vertices).map(Primitive::Polygon)
            }
            "cone" => {
                let c: ConeToml = self.deserialize(fields)?;
                Cone::new(c.base.0, c.base_radius.0, c.apex.0, c.apex_radius.0)
                    .and_then(|cone| placed(Primitive::Cone(cone), transform))
            }
            "include" => {
                let include: IncludeToml = self.deserialize(fields)?;
                let material = material.map(|m| self.material(Some(m))).transpose()?;
                return self.include(include, material, transform, nesting);
            }
            other => {
                return Err(self.error(
                    kind_span,
                    format!("expected an object type ({TYPES}), found `{other}`"),
                ));
            }
        };
        let prim = prim.map_err(|e| self.error(span, geometry_message(&e)))?;
        let material = self.material(material)?;
        self.scene.push(prim, material);
        Ok(())
    }

    /// Append the primitives of an included scene file, transformed.
    fn include(
        &mut self,
        include: IncludeToml,
        material: Option<u32>,
        transform: Option<Mat4>,
        nesting: &mut Nesting,
    ) -> Result<(), SceneError> {
        let span = include.path.span();
        let relative = include.path.into_inner();
        let path = self.path.parent().unwrap_or(Path::new("")).join(&relative);
        if nesting.stack.contains(&nesting.files.identity(&path)) {
            return Err(self.error(
                span,
                format!(
                    "expected an include that does not include itself, found a cycle through `{relative}`"
                ),
            ));
        }
        if nesting.stack.len() >= MAX_INCLUDE_DEPTH {
            return Err(self.error(
                span,
                format!(
                    "expected includes nested at most {MAX_INCLUDE_DEPTH} deep \
                     (raypack::scene::native::MAX_INCLUDE_DEPTH), found a deeper chain at `{relative}`"
                ),
            ));
        }
        let here = format!(
            " (included from {}:{})",
            self.path.display(),
            line_of(self.text.as_bytes(), span.start)
        );
        let nested = if relative.to_ascii_lowercase().ends_with(".toml") {
            load_nested(&path, nesting)
        } else {
            nesting.files.load(&path)
        };
        let included = nested.map_err(|mut e| {
            if e.line.is_none() {
                // The file could not be read at all: point at the include itself.
                return self.error(
                    span.clone(),
                    format!(
                        "expected a readable scene file at `{relative}`, found: {}",
                        e.message
                    ),
                );
            }
            e.message.push_str(&here);
            e
        })?;
        let material_base = self.scene.materials.len() as u32;
        if material.is_none() {
            self.scene.materials.extend_from_slice(&included.materials);
        }
        let first = self.scene.primitives.len() as u32;
        for (i, prim) in included.primitives.into_iter().enumerate() {
            let prim = match (prim, transform) {
                (Primitive::Triangle(t), Some(_)) => {
                    let [a, b, c] = t.vertices().map(|v| bake_point(v, transform));
                    Ok(Primitive::Triangle(Triangle::new(a, b, c)))
                }
                (prim, transform) => placed(prim, transform),
            };
            let prim = prim.map_err(|e| self.error(span.clone(), geometry_message(&e)))?;
            let material = material.unwrap_or(material_base + included.material_of[i]);
            self.scene.push(prim, material);
        }
        for (index, normals) in included.vertex_normals {
            let normals = normals.map(|n| bake_normal(n, transform));
            self.scene.vertex_normals.insert(first + index, normals);
        }
        if include.keep_lights {
            self.scene.lights.extend(included.lights.iter().map(|l| Light {
                position: bake_point(l.position, transform),
                color: l.color,
            }));
        }
        Ok(())
    }
}

/// The matrix of a `transform` table, checked to be affine and invertible.
fn transform_matrix(t: TransformToml) -> Result<Mat4, String> {
    let m = match t {
        TransformToml {
            matrix: Some(rows),
            scale: None,
            rotate: None,
            translate: None,
        } => Mat4::from_cols_array_2d(&rows.map(|row| row.map(|x| x.0))).transpose(),
        TransformToml { matrix: Some(_), .. } => {
            return Err("expected either `matrix` or `scale`/`rotate`/`translate`, found both".into());
        }
        TransformToml {
            scale,
            rotate,
            translate,
            ..
        } => {
            let scale = scale.map_or(Vec3::ONE, |s| s.0);
            let rotation = match rotate {
                Some(r) => {
                    let axis = r
                        .axis
                        .0
                        .try_normalize()
                        .ok_or("expected a non-zero rotation axis, found [0, 0, 0]")?;
                    Quat::from_axis_angle(axis, r.degrees.0.to_radians())
                }
                None => Quat::IDENTITY,
            };
            Mat4::from_scale_rotation_translation(scale, rotation, translate.map_or(Vec3::ZERO, |v| v.0))
        }
    };
    if m.row(3) != Vec4::W {
        return Err(geometry_message(&GeometryError::NotAffine));
    }
    let det = m.determinant();
    if det == 0.0 || !det.is_finite() || !m.inverse().is_finite() {
        return Err(geometry_message(&GeometryError::SingularTransform));
    }
    Ok(m)
}

/// `prim` as it is, or under `transform` (composed with an existing transform).
fn placed(prim: Primitive, transform: Option<Mat4>) -> Result<Primitive, GeometryError> {
    let Some(m) = transform else {
        return Ok(prim);
    };
    let t = match prim {
        Primitive::Transformed(inner) => Transformed::new(inner.object().clone(), m * inner.matrix())?,
        prim => Transformed::new(prim, m)?,
    };
    Ok(Primitive::Transformed(Box::new(t)))
}

/// A vertex under the transform.
fn bake_point(p: Vec3, transform: Option<Mat4>) -> Vec3 {
    transform.map_or(p, |m| m.transform_point3(p))
}

/// A shading normal under the transform: by `M⁻ᵀ`, renormalised.
fn bake_normal(n: Vec3, transform: Option<Mat4>) -> Vec3 {
    match transform {
        Some(m) => (Mat3::from_mat4(m.inverse()).transpose() * n).normalize_or_zero(),
        None => n.normalize_or_zero(),
    }
}
