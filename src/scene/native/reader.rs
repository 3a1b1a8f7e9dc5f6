//! The TOML document turned into a [`Scene`]: the header (background, camera,
//! materials, lights), then each `[[objects]]` entry in file order, following
//! includes (refusing cycles and chains deeper than [`MAX_INCLUDE_DEPTH`]).

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use serde::Deserialize;
use toml::Spanned;
use toml::de::{DeTable, DeValue, ValueDeserializer};

use crate::geometry::{Cone, Plane, Primitive, Sphere, Triangle};
use crate::scene::error::{SceneError, geometry_message};
use crate::scene::instance::Mesh;
use crate::scene::model::{CameraSpec, Light, Material, Scene};
use crate::scene::native::errors::{line_of, reword, utf8_text};
use crate::scene::native::scene_files::SceneFiles;
use crate::scene::native::schema::{
    ConeToml, FileToml, IncludeToml, InstanceToml, PlaneToml, PolygonToml, SphereToml, TomlVec3,
    TransformToml, TriangleToml,
};
use crate::scene::native::transform::{bake_normal, bake_point, placed, transform_matrix};

/// Deepest chain of TOML files including one another that [`load_from`] follows
/// (the top file counts as depth 1). Real scenes nest two or three deep; the
/// cap keeps a long generated chain from exhausting the stack. A constant:
/// raise it here if a scene needs more.
pub const MAX_INCLUDE_DEPTH: usize = 32;

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
        meshes: HashMap::new(),
        included: HashMap::new(),
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
    if reader.scene.id_count() == 0 {
        let end = text.len();
        return Err(reader.error(end..end, "expected at least one object ([[objects]]), found none"));
    }
    Ok(reader.scene)
}

/// An included file as meshes of the including scene, made once per file
/// and material override however often it is included.
#[derive(Clone)]
struct Adopted {
    /// Each mesh to place and its transform within the included file.
    placements: Vec<(u32, Mat4)>,
    /// The file's lights, for includes with `keep_lights`.
    lights: Vec<Light>,
    /// The file's own instance levels.
    depth: u32,
}

/// The reader's state while it walks the file.
struct Reader<'a> {
    path: &'a Path,
    text: &'a str,
    scene: Scene,
    /// The named meshes (`[meshes.NAME]`): their file and material override.
    meshes: HashMap<String, (Spanned<String>, Option<u32>)>,
    /// The files included so far, by identity and material override.
    included: HashMap<(PathBuf, Option<u32>), Adopted>,
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
        if let Some(TomlVec3(background)) = file.background {
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
        for (name, mesh) in file.meshes {
            let material = match mesh.material {
                Some(m) => {
                    let span = m.span();
                    let m = m.into_inner();
                    let index = self.materials.get(&m).copied().ok_or_else(|| {
                        self.error(
                            span,
                            format!("expected the name of a material defined under [materials], found `{m}`"),
                        )
                    })?;
                    Some(index)
                }
                None => None,
            };
            self.meshes.insert(name, (mesh.path, material));
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
        const TYPES: &str = "sphere, plane, triangle, polygon, cone, include or instance";
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
                Primitive::polygon(&vertices)
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
            "instance" => {
                let instance: InstanceToml = self.deserialize(fields)?;
                let name = instance.mesh.get_ref();
                let Some((path, mesh_material)) = self.meshes.get(name).cloned() else {
                    let mut names: Vec<&str> = self.meshes.keys().map(String::as_str).collect();
                    names.sort_unstable();
                    return Err(self.error(
                        instance.mesh.span(),
                        match names.is_empty() {
                            true => format!(
                                "expected a mesh defined under [meshes], found `{name}` (there are none)"
                            ),
                            false => format!(
                                "expected the name of a mesh defined under [meshes] ({}), found `{name}`",
                                names.join(", ")
                            ),
                        },
                    ));
                };
                // The object's own material overrides the mesh's.
                let material = match material {
                    Some(m) => Some(self.material(Some(m))?),
                    None => mesh_material,
                };
                let include = IncludeToml {
                    path,
                    keep_lights: false,
                };
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

    /// Make the included scene `included` meshes of this one: its own
    /// primitives one mesh, and each of its meshes one, their materials
    /// `material` or the file's (appended to this scene's).
    fn adopt(&mut self, included: Scene, material: Option<u32>, name: &str) -> Adopted {
        let material_base = self.scene.materials.len() as u32;
        if material.is_none() {
            self.scene.materials.extend_from_slice(&included.materials);
        }
        let remap = |of: &[u32]| -> Vec<u32> {
            of.iter()
                .map(|&m| material.unwrap_or(material_base + m))
                .collect()
        };
        let mut placements = Vec::new();
        if !included.primitives.is_empty() {
            let own = self.scene.add_mesh(Mesh {
                name: name.to_string(),
                material_of: remap(&included.material_of),
                primitives: included.primitives,
                vertex_normals: included.vertex_normals,
            });
            placements.push((own, Mat4::IDENTITY));
        }
        let first = self.scene.instances.meshes().len() as u32;
        for mesh in included.instances.meshes() {
            self.scene.add_mesh(Mesh {
                material_of: remap(&mesh.material_of),
                ..mesh.clone()
            });
        }
        for instance in included.instances.list() {
            placements.push((first + instance.mesh, instance.to_world));
        }
        Adopted {
            placements,
            lights: included.lights,
            depth: included.instances.depth(),
        }
    }

    /// Place an included scene file as instances (its meshes made once per
    /// file, shared by every include of it), transformed.
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
        let key = (nesting.files.identity(&path), material);
        let adopted = match self.included.get(&key) {
            Some(adopted) => adopted.clone(),
            None => {
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
                let adopted = self.adopt(included, material, &relative);
                self.included.insert(key, adopted.clone());
                adopted
            }
        };
        // Place each of the file's meshes (its own primitives, and those it
        // instances in turn, their transforms composed with this one).
        let m = transform.unwrap_or(Mat4::IDENTITY);
        for &(mesh, inner) in &adopted.placements {
            self.scene
                .place(mesh, m * inner)
                .map_err(|e| self.error(span.clone(), e.to_string()))?;
        }
        self.scene.instances.nested(adopted.depth + 1);
        if include.keep_lights {
            self.scene.lights.extend(adopted.lights.iter().map(|l| Light {
                position: bake_point(l.position, transform),
                color: l.color,
            }));
        }
        Ok(())
    }
}
