//! Wavefront OBJ meshes: `v`, `vn` and `f` statements, each face one primitive
//! in file order (a triangle, or a polygon for four or more corners; never
//! triangulated, so the numbering is the file's).
//!
//! Hand-written rather than taken from the `tobj` crate: tobj's errors carry no
//! line number, it accepts NaN coordinates, and it regroups faces into models.
//! What is read, per the OBJ specification (Wavefront, "Object Files (.obj)",
//! Appendix B1 of the Advanced Visualizer manual):
//!
//! - `v x y z [w]` or `v x y z r g b` (vertex colours): the position, which must be finite;
//! - `vn x y z`: a normal, finite;
//! - `f v1 v2 v3 …` with corners `v`, `v/vt`, `v//vn` or `v/vt/vn`; indices count
//!   from 1, negative ones back from the latest vertex (−1 is the last so far).
//!   A triangle whose three corners all name normals gets them as shading normals.
//!
//! Texture coordinates, grouping, smoothing groups and materials (`vt`, `vp`, `o`,
//! `g`, `s`, `mg`, `usemtl`, `mtllib`), points and lines (`p`, `l`) and comments are
//! skipped. Any other statement (free-form curves and surfaces, binary garbage)
//! is an error naming its line, as is every malformed number or index.
//! Gzip-compressed files are read too (detected by their magic bytes).

use std::path::Path;

use glam::Vec3;

use crate::plural;
use crate::scene::error::SceneError;
use crate::scene::input::{self, finite_f32, parse_int, quote};
use crate::scene::mesh::MeshBuilder;
use crate::scene::model::Scene;

/// Statements that carry nothing a ray tracer of this engine uses.
const SKIPPED: [&[u8]; 10] = [
    b"vt", b"vp", b"o", b"g", b"s", b"mg", b"usemtl", b"mtllib", b"p", b"l",
];

/// Read the OBJ file at `path`.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    parse(path, &input::read_file(path)?)
}

/// Read OBJ data already in memory (gzip or plain); `path` names it in errors.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<Scene, SceneError> {
    let text = input::gunzip_if_needed(path, bytes)?;
    let mut reader = ObjReader::new(path);
    let mut last_line = 1;
    for (number, line) in input::lines(&text) {
        last_line = number;
        reader
            .statement(input::strip_comment(line))
            .map_err(|m| SceneError::at(path, number, m))?;
    }
    if reader.mesh.face_count() == 0 {
        return Err(SceneError::at(
            path,
            last_line,
            format!(
                "no faces: expected `f` statements ({} vertices read)",
                reader.positions.len()
            ),
        ));
    }
    Ok(reader.mesh.finish())
}

/// The state of one pass over an OBJ file.
struct ObjReader {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    mesh: MeshBuilder,
    /// Corners of the face being read (reused between faces).
    corners: Vec<Vec3>,
    /// Their normal indices, where given.
    corner_normals: Vec<Option<usize>>,
}

impl ObjReader {
    fn new(path: &Path) -> Self {
        Self {
            positions: Vec::new(),
            normals: Vec::new(),
            mesh: MeshBuilder::new(path, 0),
            corners: Vec::new(),
            corner_normals: Vec::new(),
        }
    }

    /// Read one statement (a comment-free line); errors are messages for its line.
    fn statement(&mut self, line: &[u8]) -> Result<(), String> {
        let mut tokens = input::tokens(line);
        let Some(keyword) = tokens.next() else {
            return Ok(());
        };
        match keyword {
            b"v" => {
                let (values, count) = numbers(tokens, "v")?;
                if !matches!(count, 3 | 4 | 6) {
                    return Err(format!(
                        "`v` needs x y z (optionally w, or r g b), got {count} numbers"
                    ));
                }
                self.positions.push(Vec3::from_slice(&values));
            }
            b"vn" => {
                let (values, count) = numbers(tokens, "vn")?;
                if count != 3 {
                    return Err(format!("`vn` needs 3 numbers, got {count}"));
                }
                self.normals.push(Vec3::from_slice(&values));
            }
            b"f" => self.face(tokens)?,
            _ if SKIPPED.contains(&keyword) => {}
            _ => {
                return Err(format!(
                    "unknown statement {} (expected v, vn, f, or one of vt, vp, o, g, s, mg, usemtl, mtllib, p, l)",
                    quote(keyword)
                ));
            }
        }
        Ok(())
    }

    /// Read the corners of an `f` statement and add the face.
    fn face<'a>(&mut self, tokens: impl Iterator<Item = &'a [u8]>) -> Result<(), String> {
        self.corners.clear();
        self.corner_normals.clear();
        for corner in tokens {
            // A corner is `v`, `v/vt`, `v//vn` or `v/vt/vn`.
            let mut parts = corner.split(|&b| b == b'/');
            let v = parts.next().unwrap_or_default();
            let vt = parts.next().unwrap_or_default();
            let vn = parts.next().unwrap_or_default();
            if parts.next().is_some() || v.is_empty() {
                return Err(format!(
                    "face corner {} is not v, v/vt, v//vn or v/vt/vn",
                    quote(corner)
                ));
            }
            let position = resolve(v, self.positions.len(), ("vertex", "vertices"))?;
            if !vt.is_empty() {
                parse_int(vt)?;
            }
            let normal = match vn {
                b"" => None,
                _ => Some(resolve(vn, self.normals.len(), ("normal", "normals"))?),
            };
            self.corners.push(self.positions[position]);
            self.corner_normals.push(normal);
        }
        if self.corners.len() < 3 {
            return Err(format!(
                "a face needs at least 3 corners, got {}",
                self.corners.len()
            ));
        }
        let normals = match self.corner_normals[..] {
            [Some(a), Some(b), Some(c)] => Some([self.normals[a], self.normals[b], self.normals[c]]),
            _ => None,
        };
        self.mesh.push_face(&self.corners, normals);
        Ok(())
    }
}

/// Most numbers a `v` statement may carry (x y z r g b).
const MAX_NUMBERS: usize = 6;

/// The remaining tokens of a `v`/`vn` statement as finite numbers, and their
/// count (checked by the caller; more than [`MAX_NUMBERS`] is an error here).
fn numbers<'a>(
    tokens: impl Iterator<Item = &'a [u8]>,
    what: &str,
) -> Result<([f32; MAX_NUMBERS], usize), String> {
    let mut values = [0.0; MAX_NUMBERS];
    let mut count = 0;
    for token in tokens {
        if count == MAX_NUMBERS {
            return Err(format!("`{what}` has more than {MAX_NUMBERS} numbers"));
        }
        values[count] = finite_f32(token).map_err(|m| format!("`{what}`: {m}"))?;
        count += 1;
    }
    Ok((values, count))
}

/// An OBJ index (1-based, or negative counting back from the latest) into a list
/// of `count` items defined so far, as a 0-based index.
fn resolve(token: &[u8], count: usize, (what, whats): (&str, &str)) -> Result<usize, String> {
    let index = parse_int(token).map_err(|m| format!("{what} index: {m}"))?;
    if index == 0 {
        return Err(format!("{what} index 0 is not valid (OBJ indices start at 1)"));
    }
    let resolved = if index > 0 {
        index - 1
    } else {
        count as i64 + index
    };
    if !(0..count as i64).contains(&resolved) {
        return Err(format!(
            "{what} index {index} out of range ({} defined so far)",
            plural::count(count as u64, what, whats)
        ));
    }
    Ok(resolved as usize)
}
