//! The NFF reader (Eric Haines' Neutral File Format, the format of the Standard
//! Procedural Databases; summarised in `docs/nff.md`).
//!
//! NFF is a stream of white-space separated tokens; `#` starts a comment to the
//! end of the line. Each entity is a keyword followed by a fixed number of
//! fields, so the reader works on tokens, not lines, and tracks the line of
//! every token for its errors (`file:line: expected …, found …`). Entities:
//!
//! | NFF | becomes |
//! | --- | --- |
//! | `v` | the camera ([`CameraSpec`]), resolution kept; `hither` is read and not used |
//! | `b` | the background colour |
//! | `l` | a [`Light`] (white when no colour is given) |
//! | `f` | a new [`Material`] for the objects that follow |
//! | `s` | a [`Sphere`]; a negative radius makes it [inside-only](Sphere::inside_only) |
//! | `p` | a [`Polygon`] (concave allowed; < 3 vertices or collinear first three are errors); of 3 vertices a [`Triangle`] ([`Primitive::polygon`]) |
//! | `pp` | 3 vertices: a [`Triangle`] with its vertex normals in [`Scene::vertex_normals`]; more: a flat [`Polygon`] (the normals are dropped) |
//! | `c` | a [`Cone`] |
//!
//! Each `s`, `p`, `pp` and `c` is one primitive, numbered in file order.
//! Objects before the first `f` get the default material (white, diffuse).
//! A zero-area `pp` triangle (the SPD teapot has some at its poles) is kept,
//! never hit, so that the numbering still matches the file; vertex normals
//! are normalised, and a zero one stays zero.

use std::path::Path;

use glam::Vec3;

use crate::geometry::{Cone, GeometryError, Polygon, Primitive, Sphere, Triangle};
use crate::scene::error::{SceneError, geometry_message};
use crate::scene::model::{CameraSpec, Light, Material, Scene};

/// Read the NFF file at `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read(path).map_err(|e| SceneError::file(path, format!("cannot read: {e}")))?;
    parse(path, &text)
}

/// Parse NFF text; `path` names the file in errors and in [`Scene::source`].
pub fn parse(path: &Path, text: &[u8]) -> Result<Scene, SceneError> {
    let mut reader = Reader {
        tokens: Tokens {
            text,
            pos: 0,
            line: 1,
            last: 1,
        },
        path,
        scene: Scene {
            source: path.display().to_string(),
            ..Scene::default()
        },
        material: None,
        camera_line: None,
        vertices: Vec::new(),
    };
    while let Some((token, line)) = reader.tokens.next() {
        reader.entity(token, line)?;
    }
    if reader.scene.primitives.is_empty() {
        let found = if reader.tokens.is_blank() {
            "an empty file"
        } else {
            "none"
        };
        return Err(reader.error_here(format!(
            "expected at least one object (`s`, `p`, `pp` or `c`), found {found}"
        )));
    }
    Ok(reader.scene)
}

/// White-space separated tokens with their line numbers; comments skipped.
#[derive(Clone, Copy)]
struct Tokens<'a> {
    text: &'a [u8],
    pos: usize,
    /// Line of `pos` (1-based).
    line: usize,
    /// Line of the last token returned (1 before any).
    last: usize,
}

impl<'a> Tokens<'a> {
    /// The next token and its line, or None at the end of the text.
    #[inline]
    fn next(&mut self) -> Option<(&'a [u8], usize)> {
        let text = self.text;
        // Skip white space and comments, counting lines.
        loop {
            match text.get(self.pos) {
                None => return None,
                Some(b'\n') => self.line += 1,
                Some(b'#') => {
                    while self.pos < text.len() && text[self.pos] != b'\n' {
                        self.pos += 1;
                    }
                    continue;
                }
                Some(c) if c.is_ascii_whitespace() => {}
                Some(_) => break,
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < text.len() && !text[self.pos].is_ascii_whitespace() && text[self.pos] != b'#' {
            self.pos += 1;
        }
        self.last = self.line;
        Some((&text[start..self.pos], self.line))
    }

    /// The next token without consuming it.
    #[inline]
    fn peek(&self) -> Option<&'a [u8]> {
        let mut ahead = *self;
        ahead.next().map(|(token, _)| token)
    }

    /// True when the whole text holds no token (empty, blank or only comments).
    fn is_blank(&self) -> bool {
        Tokens {
            pos: 0,
            line: 1,
            ..*self
        }
        .next()
        .is_none()
    }
}

/// How a token is shown in an error: quoted and shortened, or as binary.
fn describe(token: Option<&[u8]>) -> String {
    const SHOWN: usize = 24;
    let Some(token) = token else {
        return "end of file".into();
    };
    match std::str::from_utf8(token) {
        Ok(s) if !s.chars().any(|c| c.is_control()) => {
            let short: String = s.chars().take(SHOWN).collect();
            let more = if s.chars().count() > SHOWN { "…" } else { "" };
            format!("`{short}{more}`")
        }
        _ => format!(
            "binary data ({})",
            token
                .iter()
                .take(8)
                .map(|b| format!("{b:02x}"))
                .collect::<Vec<_>>()
                .join(" ")
        ),
    }
}

/// The reader's state while it walks the entities.
struct Reader<'a> {
    tokens: Tokens<'a>,
    path: &'a Path,
    scene: Scene,
    /// Material of the objects that follow (the last `f`), None before any.
    material: Option<u32>,
    /// Line of the `v` entity once one was read.
    camera_line: Option<usize>,
    /// Scratch buffer for polygon vertices.
    vertices: Vec<Vec3>,
}

impl<'a> Reader<'a> {
    fn error(&self, line: usize, message: String) -> SceneError {
        SceneError::at(self.path, line, message)
    }

    /// An error at the line of the last token read (where a truncated file ends).
    fn error_here(&self, message: String) -> SceneError {
        SceneError::at(self.path, self.tokens.last, message)
    }

    /// The next token, which must exist: `what` says what was expected.
    #[inline]
    fn token(&mut self, what: &dyn Fn() -> String) -> Result<(&'a [u8], usize), SceneError> {
        match self.tokens.next() {
            Some(t) => Ok(t),
            None => Err(self.error_here(format!("expected {}, found end of file", what()))),
        }
    }

    /// A finite number; `what` names it for the error.
    #[inline]
    fn number(&mut self, what: &dyn Fn() -> String) -> Result<f32, SceneError> {
        let (token, line) = self.token(what)?;
        let parsed = std::str::from_utf8(token)
            .ok()
            .and_then(|s| s.parse::<f32>().ok());
        match parsed {
            Some(x) if x.is_finite() => Ok(x),
            Some(_) => Err(self.error(
                line,
                format!(
                    "expected {} (a finite number), found {}",
                    what(),
                    describe(Some(token))
                ),
            )),
            None => Err(self.error(
                line,
                format!("expected {} (a number), found {}", what(), describe(Some(token))),
            )),
        }
    }

    /// Three finite numbers.
    #[inline]
    fn vec3(&mut self, what: &dyn Fn() -> String) -> Result<Vec3, SceneError> {
        const AXES: [&str; 3] = ["x", "y", "z"];
        let mut v = [0.0; 3];
        for (k, value) in v.iter_mut().enumerate() {
            *value = self.number(&|| format!("{} of {}", AXES[k], what()))?;
        }
        Ok(Vec3::from_array(v))
    }

    /// A colour: three finite numbers.
    fn color(&mut self, what: &dyn Fn() -> String) -> Result<Vec3, SceneError> {
        const CHANNELS: [&str; 3] = ["red", "green", "blue"];
        let mut v = [0.0; 3];
        for (k, value) in v.iter_mut().enumerate() {
            *value = self.number(&|| format!("the {} of {}", CHANNELS[k], what()))?;
        }
        Ok(Vec3::from_array(v))
    }

    /// An unsigned integer of at least `min`.
    fn integer(&mut self, min: u32, what: &dyn Fn() -> String) -> Result<u32, SceneError> {
        let (token, line) = self.token(what)?;
        let parsed = std::str::from_utf8(token)
            .ok()
            .and_then(|s| s.parse::<u32>().ok());
        match parsed {
            Some(n) if n >= min => Ok(n),
            _ => Err(self.error(
                line,
                format!(
                    "expected {} (an integer ≥ {min}), found {}",
                    what(),
                    describe(Some(token))
                ),
            )),
        }
    }

    /// The sub-keyword `word` of the `v` entity.
    fn sub_keyword(&mut self, word: &str) -> Result<(), SceneError> {
        let what =
            || format!("`{word}` (the camera's `v` entity lists from, at, up, angle, hither, resolution)");
        let (token, line) = self.token(&what)?;
        if token != word.as_bytes() {
            return Err(self.error(
                line,
                format!("expected {}, found {}", what(), describe(Some(token))),
            ));
        }
        Ok(())
    }

    /// The material for the next object (the default one before any `f`).
    fn current_material(&mut self) -> u32 {
        *self.material.get_or_insert_with(|| {
            self.scene.materials.push(Material::default());
            (self.scene.materials.len() - 1) as u32
        })
    }

    /// Append a primitive built from the entity at `line`.
    fn push(&mut self, prim: Result<Primitive, GeometryError>, line: usize) -> Result<u32, SceneError> {
        let prim = prim.map_err(|e| self.error(line, geometry_message(&e)))?;
        let material = self.current_material();
        Ok(self.scene.push(prim, material))
    }

    /// `n` polygon vertices into the scratch buffer (with their normals when `normals` is set).
    fn vertices(&mut self, kind: &str, n: usize, normals: Option<&mut [Vec3; 3]>) -> Result<(), SceneError> {
        self.vertices.clear();
        let mut normals = normals;
        for i in 0..n {
            let vertex = self.vec3(&|| format!("{kind} vertex {} of {n}", i + 1))?;
            self.vertices.push(vertex);
            if let Some(normals) = normals.as_deref_mut() {
                let normal = self.vec3(&|| format!("{kind} normal {} of {n}", i + 1))?;
                if let Some(slot) = normals.get_mut(i) {
                    *slot = normal.normalize_or_zero();
                }
            }
        }
        Ok(())
    }

    /// Read one entity whose keyword `token` is on `line`.
    fn entity(&mut self, token: &[u8], line: usize) -> Result<(), SceneError> {
        match token {
            b"v" => self.camera(line),
            b"b" => {
                self.scene.background = self.color(&|| "the background colour".into())?;
                Ok(())
            }
            b"l" => {
                let position = self.vec3(&|| "the light position".into())?;
                // The colour is optional: present when a number follows.
                let has_color = self
                    .tokens
                    .peek()
                    .and_then(|t| std::str::from_utf8(t).ok())
                    .is_some_and(|s| s.parse::<f32>().is_ok());
                let color = if has_color {
                    self.color(&|| "the light colour".into())?
                } else {
                    Vec3::ONE
                };
                self.scene.lights.push(Light { position, color });
                Ok(())
            }
            b"f" => {
                let color = self.color(&|| "the material colour".into())?;
                let mut fields = [0.0; 5];
                const NAMES: [&str; 5] = ["Kd", "Ks", "Shine", "T", "index_of_refraction"];
                for (k, field) in fields.iter_mut().enumerate() {
                    *field = self.number(&|| format!("the material's {}", NAMES[k]))?;
                }
                let [kd, ks, shine, transmittance, ior] = fields;
                self.scene.materials.push(Material {
                    color,
                    kd,
                    ks,
                    shine,
                    transmittance,
                    ior,
                });
                self.material = Some((self.scene.materials.len() - 1) as u32);
                Ok(())
            }
            b"s" => {
                let center = self.vec3(&|| "the sphere centre".into())?;
                let radius = self.number(&|| "the sphere radius".into())?;
                if radius == 0.0 {
                    return Err(self.error(line, "expected a non-zero sphere radius, found 0".into()));
                }
                let sphere = if radius < 0.0 {
                    Sphere::inside_only(center, radius)
                } else {
                    Sphere::new(center, radius)
                };
                self.push(Ok(Primitive::Sphere(sphere)), line).map(drop)
            }
            b"p" => {
                let n = self.integer(3, &|| "the polygon's vertex count".into())? as usize;
                self.vertices("polygon", n, None)?;
                let polygon = Primitive::polygon(&self.vertices);
                self.push(polygon, line).map(drop)
            }
            b"pp" => {
                let n = self.integer(3, &|| "the patch's vertex count".into())? as usize;
                let mut normals = [Vec3::ZERO; 3];
                self.vertices("patch", n, Some(&mut normals))?;
                if n == 3 {
                    let [a, b, c] = [self.vertices[0], self.vertices[1], self.vertices[2]];
                    let index = self.push(Ok(Primitive::Triangle(Triangle::new(a, b, c))), line)?;
                    self.scene.vertex_normals.insert(index, normals);
                    Ok(())
                } else {
                    // More than three vertices: a flat polygon; the polygon
                    // kernel has no per-vertex normals to interpolate.
                    let polygon = Polygon::new(&self.vertices).map(Primitive::Polygon);
                    self.push(polygon, line).map(drop)
                }
            }
            b"c" => {
                let base = self.vec3(&|| "the cone's base centre".into())?;
                let base_radius = self.number(&|| "the cone's base radius".into())?;
                let apex = self.vec3(&|| "the cone's apex centre".into())?;
                let apex_radius = self.number(&|| "the cone's apex radius".into())?;
                let cone = Cone::new(base, base_radius, apex, apex_radius).map(Primitive::Cone);
                self.push(cone, line).map(drop)
            }
            other => Err(self.error(
                line,
                format!(
                    "expected an NFF keyword (v, b, l, f, s, p, pp, c), found {}",
                    describe(Some(other))
                ),
            )),
        }
    }

    /// The `v` entity: from, at, up, angle, hither, resolution, in this order.
    ///
    /// NFF's `angle` is the full field of view from the centre of the top pixel
    /// row to the centre of the bottom row (and likewise across). The lecture's
    /// camera spans the image edge to edge, and the image plane is flat, so for
    /// H rows the half-extents scale with the pixel span:
    /// `tan(fovy/2) = tan(angle/2)·H/(H−1)`, and `tan(fovx/2) = tan(angle/2)·W/(W−1)`.
    fn camera(&mut self, line: usize) -> Result<(), SceneError> {
        if let Some(first) = self.camera_line {
            return Err(self.error(
                line,
                format!("expected one camera (`v`), found a second one (the first is on line {first})"),
            ));
        }
        self.camera_line = Some(line);
        self.sub_keyword("from")?;
        let eye = self.vec3(&|| "the camera's `from` point".into())?;
        self.sub_keyword("at")?;
        let center = self.vec3(&|| "the camera's `at` point".into())?;
        self.sub_keyword("up")?;
        let up = self.vec3(&|| "the camera's `up` vector".into())?;
        self.sub_keyword("angle")?;
        let angle = self.number(&|| "the camera's angle in degrees".into())?;
        if !(angle > 0.0 && angle < 180.0) {
            return Err(self.error_here(format!("expected a camera angle in (0°, 180°), found {angle}")));
        }
        self.sub_keyword("hither")?;
        self.number(&|| "the camera's hither distance".into())?;
        self.sub_keyword("resolution")?;
        // At least 2×2: the angle spans pixel centres, so one row spans nothing.
        let width = self.integer(2, &|| "the image width".into())?;
        let height = self.integer(2, &|| "the image height".into())?;
        let edge_to_edge = |pixels: u32| {
            let half = (angle.to_radians() * 0.5).tan() * pixels as f32 / (pixels - 1) as f32;
            2.0 * half.atan().to_degrees()
        };
        let spec = CameraSpec {
            eye,
            center,
            up,
            fovx: edge_to_edge(width),
            fovy: edge_to_edge(height),
            width,
            height,
        };
        spec.camera()
            .map_err(|e| self.error(line, format!("expected a usable camera, found one where {e}")))?;
        self.scene.camera = Some(spec);
        Ok(())
    }
}
