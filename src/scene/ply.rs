//! PLY meshes, ASCII and binary (G. Turk, "The PLY Polygon File Format",
//! Stanford, 1994), plain or gzip-compressed (detected by magic bytes): the
//! format the Stanford scanning repository ships its models in.
//!
//! What is read:
//!
//! - the `vertex` element's `x y z` (any scalar type, usually `float`) and, when
//!   all three are present, `nx ny nz` as shading normals; every other vertex
//!   property is skipped by its declared type;
//! - the `face` element's `vertex_indices` (or `vertex_index`) list, with any
//!   integer count and index types; each face is one primitive, in file order
//!   (a triangle, or a polygon for four or more corners), so face `i` of the file
//!   is primitive `i` of the scene;
//! - any other element is skipped by its declared property types.
//!
//! The file is read into memory whole and parsed in place: no allocation per
//! value, binary values decoded straight from the byte slice, ASCII numbers
//! parsed from their token (`float`s as `f32` directly, so ASCII and binary
//! copies of one mesh give the same bits).
//!
//! Errors say where: header problems and ASCII body problems with their line
//! (`file:12: vertex 3: …`), binary body problems with the element and its
//! 0-based index (`file: face 123: index 99999 out of range (842 vertices)`);
//! truncation, wrong value counts, non-numbers, NaN/infinite coordinates and bad
//! indices all fail, never silently produce a different mesh. The `vertex`
//! element must come before the `face` element (every writer we know does so),
//! so indices can be checked as faces are read.

use std::path::Path;

use glam::Vec3;

use crate::scene::error::SceneError;
use crate::scene::input::{self, parse_f32, parse_f64, parse_int, quote};
use crate::scene::mesh::MeshBuilder;
use crate::scene::model::Scene;

/// Read the PLY file at `path` (plain or gzip).
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    parse(path, &input::read_file(path)?)
}

/// Read PLY data already in memory (plain or gzip); `path` names it in errors.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<Scene, SceneError> {
    let bytes = input::gunzip_if_needed(path, bytes)?;
    let header = Header::parse(path, &bytes)?;
    let body = &bytes[header.body_start..];
    let n = body.len();
    match header.format {
        Format::Ascii => read_body(path, &header, n, AsciiBody::new(body, header.body_line)),
        Format::BinaryLittleEndian => read_body(path, &header, n, BinaryBody::<false>::new(body)),
        Format::BinaryBigEndian => read_body(path, &header, n, BinaryBody::<true>::new(body)),
    }
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    /// The type named in a header (both the 1994 names and the sized ones).
    fn from_name(name: &[u8]) -> Option<Self> {
        Some(match name {
            b"char" | b"int8" => Self::I8,
            b"uchar" | b"uint8" => Self::U8,
            b"short" | b"int16" => Self::I16,
            b"ushort" | b"uint16" => Self::U16,
            b"int" | b"int32" => Self::I32,
            b"uint" | b"uint32" => Self::U32,
            b"float" | b"float32" => Self::F32,
            b"double" | b"float64" => Self::F64,
            _ => return None,
        })
    }

    /// Size in bytes in a binary body.
    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// The range of an integer type; None for floating-point types.
    fn int_range(self) -> Option<(i64, i64)> {
        match self {
            Self::I8 => Some((i8::MIN.into(), i8::MAX.into())),
            Self::U8 => Some((0, u8::MAX.into())),
            Self::I16 => Some((i16::MIN.into(), i16::MAX.into())),
            Self::U16 => Some((0, u16::MAX.into())),
            Self::I32 => Some((i32::MIN.into(), i32::MAX.into())),
            Self::U32 => Some((0, u32::MAX.into())),
            Self::F32 | Self::F64 => None,
        }
    }
}

/// How a property's values are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layout {
    /// One value.
    Scalar(Scalar),
    /// A count, then that many items.
    List { count: Scalar, item: Scalar },
}

/// A `property` line of the header.
#[derive(Debug)]
struct Property {
    name: String,
    layout: Layout,
    /// Header line, for errors about it.
    line: usize,
}

/// An `element` line of the header and its properties.
#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
    /// Header line, for errors about it.
    line: usize,
}

impl Element {
    /// The fewest body bytes one instance can take, to bound reservations by
    /// what the data could hold (a corrupt count must not reserve gigabytes).
    fn min_bytes(&self, ascii: bool) -> usize {
        let bytes: usize = self
            .properties
            .iter()
            .map(|p| match (ascii, p.layout) {
                (true, _) => 2,
                (false, Layout::Scalar(s)) => s.size(),
                (false, Layout::List { count, .. }) => count.size(),
            })
            .sum();
        bytes.max(1)
    }

    /// The scalar property called `name`, if any; a list of that name is an error.
    fn scalar(&self, name: &str) -> Result<Option<usize>, String> {
        match self.properties.iter().position(|p| p.name == name) {
            Some(i) if matches!(self.properties[i].layout, Layout::List { .. }) => {
                Err(format!("vertex property `{name}` must be a scalar, not a list"))
            }
            found => Ok(found),
        }
    }
}

/// The body encoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// A parsed header.
#[derive(Debug)]
struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body_start: usize,
    /// Line number of the body's first line (ASCII bodies).
    body_line: usize,
    /// Line of `end_header`.
    end_line: usize,
}

impl Header {
    /// Parse and check the header: `ply`, `format`, `element`/`property` lines,
    /// `end_header`; a `vertex` element with `x y z` before a `face` element with
    /// an integer `vertex_indices` list.
    fn parse(path: &Path, bytes: &[u8]) -> Result<Self, SceneError> {
        let at = |line: usize, m: String| SceneError::at(path, line, m);
        if bytes.is_empty() {
            return Err(at(1, "empty file (expected a PLY header)".into()));
        }
        if !(bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")) {
            let first = bytes.split(|&b| b == b'\n').next().unwrap_or_default();
            return Err(at(
                1,
                format!(
                    "not a PLY file: expected `ply` on the first line, found {}",
                    quote(first)
                ),
            ));
        }
        let mut format = None;
        let mut elements: Vec<Element> = Vec::new();
        let mut pos = 0;
        let mut number = 0;
        loop {
            let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
                return Err(at(
                    number + 1,
                    "the header does not end: `end_header` missing (truncated file?)".into(),
                ));
            };
            number += 1;
            let raw = &bytes[pos..pos + len];
            pos += len + 1;
            if number == 1 {
                continue;
            }
            let line = raw.strip_suffix(b"\r").unwrap_or(raw);
            let mut tokens = input::tokens(line);
            match tokens.next() {
                None | Some(b"comment" | b"obj_info") => {}
                Some(b"format") => {
                    let f = match tokens.next() {
                        Some(b"ascii") => Format::Ascii,
                        Some(b"binary_little_endian") => Format::BinaryLittleEndian,
                        Some(b"binary_big_endian") => Format::BinaryBigEndian,
                        other => {
                            return Err(at(
                                number,
                                format!(
                                    "unknown format {} (expected ascii, binary_little_endian or binary_big_endian)",
                                    quote(other.unwrap_or_default())
                                ),
                            ));
                        }
                    };
                    if tokens.next() != Some(b"1.0") || tokens.next().is_some() {
                        return Err(at(number, "expected `format <encoding> 1.0`".into()));
                    }
                    format = Some(f);
                }
                Some(b"element") => {
                    let (Some(name), Some(count), None) = (tokens.next(), tokens.next(), tokens.next())
                    else {
                        return Err(at(number, "expected `element <name> <count>`".into()));
                    };
                    let count = parse_int(count)
                        .ok()
                        .filter(|&c| (0..=u32::MAX as i64).contains(&c))
                        .ok_or_else(|| {
                            at(number, format!("element count {} is not a count", quote(count)))
                        })?;
                    elements.push(Element {
                        name: String::from_utf8_lossy(name).into_owned(),
                        count: count as usize,
                        properties: Vec::new(),
                        line: number,
                    });
                }
                Some(b"property") => {
                    let element = elements
                        .last_mut()
                        .ok_or_else(|| at(number, "`property` before any `element`".into()))?;
                    let property = Self::property(tokens).map_err(|m| at(number, m))?;
                    element.properties.push(Property {
                        line: number,
                        ..property
                    });
                }
                Some(b"end_header") => break,
                Some(other) => {
                    return Err(at(
                        number,
                        format!(
                            "unknown header line {} (expected format, comment, obj_info, element, property or end_header)",
                            quote(other)
                        ),
                    ));
                }
            }
        }
        let format = format.ok_or_else(|| at(number, "the header has no `format` line".into()))?;
        let header = Self {
            format,
            elements,
            body_start: pos,
            body_line: number + 1,
            end_line: number,
        };
        header.check(path)?;
        Ok(header)
    }

    /// A `property` line after its keyword: `<type> <name>` or
    /// `list <count type> <item type> <name>`.
    fn property<'a>(mut tokens: impl Iterator<Item = &'a [u8]>) -> Result<Property, String> {
        let scalar = |t: Option<&[u8]>| {
            let t = t.unwrap_or_default();
            Scalar::from_name(t).ok_or_else(|| {
                format!(
                    "unknown property type {} (expected char, uchar, short, ushort, int, uint, float, double)",
                    quote(t)
                )
            })
        };
        let layout = match tokens.next() {
            Some(b"list") => {
                let count = scalar(tokens.next())?;
                let item = scalar(tokens.next())?;
                if count.int_range().is_none() {
                    return Err("a list count must have an integer type".into());
                }
                Layout::List { count, item }
            }
            t => Layout::Scalar(scalar(t)?),
        };
        let (Some(name), None) = (tokens.next(), tokens.next()) else {
            return Err("expected `property <type> <name>` or `property list <type> <type> <name>`".into());
        };
        Ok(Property {
            name: String::from_utf8_lossy(name).into_owned(),
            layout,
            line: 0,
        })
    }

    /// Check the elements this reader needs.
    fn check(&self, path: &Path) -> Result<(), SceneError> {
        let at = |line: usize, m: String| SceneError::at(path, line, m);
        let find = |name: &str| -> Result<Option<usize>, SceneError> {
            let mut found = self.elements.iter().enumerate().filter(|(_, e)| e.name == name);
            let first = found.next().map(|(i, _)| i);
            match found.next() {
                Some((_, e)) => Err(at(e.line, format!("a second `{name}` element"))),
                None => Ok(first),
            }
        };
        let vertex =
            find("vertex")?.ok_or_else(|| at(self.end_line, "no `vertex` element in the header".into()))?;
        let face = find("face")?.ok_or_else(|| {
            at(
                self.end_line,
                "no `face` element in the header: nothing to ray trace (a point cloud?)".into(),
            )
        })?;
        if face < vertex {
            return Err(at(
                self.elements[face].line,
                "the `face` element comes before the `vertex` element (not supported)".into(),
            ));
        }
        let v = &self.elements[vertex];
        for name in ["x", "y", "z"] {
            if v.scalar(name).map_err(|m| at(v.line, m))?.is_none() {
                return Err(at(v.line, format!("the vertex element has no property `{name}`")));
            }
        }
        let f = &self.elements[face];
        let Some(list) = f.properties.iter().find(|p| is_index_list(&p.name)) else {
            return Err(at(f.line, "the face element has no `vertex_indices` list".into()));
        };
        match list.layout {
            Layout::List { item, .. } if item.int_range().is_some() => Ok(()),
            _ => Err(at(
                list.line,
                format!("`{}` must be a list of integers", list.name),
            )),
        }
    }
}

/// The face property that lists corner indices.
fn is_index_list(name: &str) -> bool {
    name == "vertex_indices" || name == "vertex_index"
}

/// What the reader does with a property's values.
#[derive(Clone, Copy, Debug)]
enum Role {
    /// Read and drop.
    Skip,
    /// Coordinate `k` of the position.
    Position(usize),
    /// Component `k` of the normal.
    Normal(usize),
    /// The face's corner indices.
    Corners,
}

/// The values of a body, in order, whatever the encoding. Messages returned
/// are completed with the element and its index by the caller.
trait Body {
    /// Start the next element instance.
    fn begin(&mut self) -> Result<(), String>;
    /// The next value, of type `ty`, for the property called `what`.
    fn value(&mut self, ty: Scalar, what: &str) -> Result<f64, String>;
    /// Finish an element instance.
    fn end(&mut self) -> Result<(), String>;
    /// Check that nothing but white space follows the last element.
    fn finish(&mut self) -> Result<(), String>;
    /// The line being read, where the encoding has lines.
    fn line(&self) -> Option<usize>;
}

/// Read every element of the body into a scene.
fn read_body<B: Body>(
    path: &Path,
    header: &Header,
    body_bytes: usize,
    mut body: B,
) -> Result<Scene, SceneError> {
    let ascii = header.format == Format::Ascii;
    let mut positions: Vec<Vec3> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut mesh: Option<MeshBuilder> = None;
    // Corners of the face being read, and their vertex indices (reused).
    let mut corners: Vec<Vec3> = Vec::new();
    let mut corner_ids: Vec<usize> = Vec::new();
    for element in &header.elements {
        let roles = roles(element);
        let has_normals = roles.iter().filter(|r| matches!(r, Role::Normal(_))).count() == 3;
        let capacity = element.count.min(body_bytes / element.min_bytes(ascii));
        let is_vertex = element.name == "vertex";
        let is_face = element.name == "face";
        if is_vertex {
            positions.reserve(capacity);
            if has_normals {
                normals.reserve(capacity);
            }
        }
        if is_face {
            mesh = Some(MeshBuilder::new(path, capacity));
        }
        if element.properties.is_empty() && !ascii {
            // Instances without properties hold no bytes in a binary body: no
            // data bounds their count (up to 2^64 − 1), so do not loop over them.
            // (In ASCII each is a line, which the file must hold.) The vertex
            // and face elements always have properties.
            continue;
        }
        for index in 0..element.count {
            let fail = |body: &B, m: String| {
                let m = format!("{} {index}: {m}", element.name);
                match body.line() {
                    Some(line) => SceneError::at(path, line, m),
                    None => SceneError::file(path, m),
                }
            };
            body.begin().map_err(|m| {
                fail(
                    &body,
                    format!(
                        "{m}: the header declares {} {} elements",
                        element.count, element.name
                    ),
                )
            })?;
            let mut position = [0.0f32; 3];
            let mut normal = [0.0f32; 3];
            corners.clear();
            corner_ids.clear();
            for (property, role) in element.properties.iter().zip(&roles) {
                let what = property.name.as_str();
                match (property.layout, *role) {
                    (Layout::Scalar(ty), Role::Position(k)) => {
                        position[k] = body.value(ty, what).map_err(|m| fail(&body, m))? as f32;
                    }
                    (Layout::Scalar(ty), Role::Normal(k)) => {
                        normal[k] = body.value(ty, what).map_err(|m| fail(&body, m))? as f32;
                    }
                    (Layout::Scalar(ty), _) => {
                        body.value(ty, what).map_err(|m| fail(&body, m))?;
                    }
                    (Layout::List { count, item }, role) => {
                        let n = body.value(count, what).map_err(|m| fail(&body, m))?;
                        if n < 0.0 {
                            return Err(fail(&body, format!("`{what}` has a negative length {n}")));
                        }
                        for _ in 0..n as u64 {
                            let v = body.value(item, what).map_err(|m| fail(&body, m))?;
                            if matches!(role, Role::Corners) {
                                let id = v as i64;
                                if !(0..positions.len() as i64).contains(&id) {
                                    return Err(fail(
                                        &body,
                                        format!("index {id} out of range ({} vertices)", positions.len()),
                                    ));
                                }
                                corner_ids.push(id as usize);
                                corners.push(positions[id as usize]);
                            }
                        }
                    }
                }
            }
            body.end().map_err(|m| fail(&body, m))?;
            if is_vertex {
                let p = Vec3::from_array(position);
                if !p.is_finite() {
                    return Err(fail(&body, format!("non-finite position {p}")));
                }
                positions.push(p);
                if has_normals {
                    let n = Vec3::from_array(normal);
                    if !n.is_finite() {
                        return Err(fail(&body, format!("non-finite normal {n}")));
                    }
                    normals.push(n);
                }
            } else if let (true, Some(mesh)) = (is_face, mesh.as_mut()) {
                if corners.len() < 3 {
                    return Err(fail(
                        &body,
                        format!("a face needs at least 3 corners, got {}", corners.len()),
                    ));
                }
                let shading = match corner_ids[..] {
                    [a, b, c] if !normals.is_empty() => Some([normals[a], normals[b], normals[c]]),
                    _ => None,
                };
                mesh.push_face(&corners, shading);
            }
        }
    }
    body.finish().map_err(|m| match body.line() {
        Some(line) => SceneError::at(path, line, m),
        None => SceneError::file(path, m),
    })?;
    let mesh = mesh.expect("the header check guarantees a face element");
    if mesh.face_count() == 0 {
        return Err(SceneError::at(
            path,
            header.end_line,
            "the face element is empty (0 faces)",
        ));
    }
    Ok(mesh.finish())
}

/// The role of each property of an element.
fn roles(element: &Element) -> Vec<Role> {
    element
        .properties
        .iter()
        .map(|p| match (element.name.as_str(), p.name.as_str(), p.layout) {
            ("vertex", "x", Layout::Scalar(_)) => Role::Position(0),
            ("vertex", "y", Layout::Scalar(_)) => Role::Position(1),
            ("vertex", "z", Layout::Scalar(_)) => Role::Position(2),
            ("vertex", "nx", Layout::Scalar(_)) => Role::Normal(0),
            ("vertex", "ny", Layout::Scalar(_)) => Role::Normal(1),
            ("vertex", "nz", Layout::Scalar(_)) => Role::Normal(2),
            ("face", name, Layout::List { .. }) if is_index_list(name) => Role::Corners,
            _ => Role::Skip,
        })
        .collect()
}

/// An ASCII body: one element instance per line, values separated by white
/// space; blank lines are skipped.
struct AsciiBody<'a> {
    /// The body after the current line.
    rest: &'a [u8],
    /// Tokens left on the current line.
    tokens: std::slice::Split<'a, u8, fn(&u8) -> bool>,
    /// Number of the current line (past the end: the line after the last).
    line: usize,
}

impl<'a> AsciiBody<'a> {
    fn new(body: &'a [u8], first_line: usize) -> Self {
        Self {
            rest: body,
            tokens: Self::split(b""),
            line: first_line - 1,
        }
    }

    /// The tokens of a line (empty ones included; [`AsciiBody::token`] drops them).
    fn split(line: &'a [u8]) -> std::slice::Split<'a, u8, fn(&u8) -> bool> {
        line.split(u8::is_ascii_whitespace as fn(&u8) -> bool)
    }

    /// The next token of the current line.
    #[inline]
    fn token(&mut self) -> Option<&'a [u8]> {
        self.tokens.by_ref().find(|t| !t.is_empty())
    }

    /// Move to the next non-blank line; false at the end of the body.
    fn next_line(&mut self) -> bool {
        self.line += 1;
        while !self.rest.is_empty() {
            let end = self
                .rest
                .iter()
                .position(|&b| b == b'\n')
                .unwrap_or(self.rest.len());
            let line = &self.rest[..end];
            self.rest = self.rest.get(end + 1..).unwrap_or_default();
            if line.iter().any(|b| !b.is_ascii_whitespace()) {
                self.tokens = Self::split(line);
                return true;
            }
            self.line += 1;
        }
        false
    }
}

impl Body for AsciiBody<'_> {
    fn begin(&mut self) -> Result<(), String> {
        if self.next_line() {
            Ok(())
        } else {
            Err("unexpected end of file (truncated?)".into())
        }
    }

    #[inline]
    fn value(&mut self, ty: Scalar, what: &str) -> Result<f64, String> {
        let token = self
            .token()
            .ok_or_else(|| format!("the line ends before a value of `{what}` (too few values)"))?;
        let value = match ty.int_range() {
            Some((lo, hi)) => parse_int(token).and_then(|v| {
                if (lo..=hi).contains(&v) {
                    Ok(v as f64)
                } else {
                    Err(format!("{v} does not fit its type ({lo} to {hi})"))
                }
            }),
            None if ty == Scalar::F32 => parse_f32(token).map(f64::from),
            None => parse_f64(token),
        };
        value.map_err(|m| format!("`{what}`: {m}"))
    }

    fn end(&mut self) -> Result<(), String> {
        match self.token() {
            None => Ok(()),
            Some(t) => Err(format!(
                "unexpected value {} after the last property (too many values)",
                quote(t)
            )),
        }
    }

    fn finish(&mut self) -> Result<(), String> {
        if self.next_line() {
            return Err("unexpected data after the last element (does the header count too few?)".into());
        }
        Ok(())
    }

    fn line(&self) -> Option<usize> {
        Some(self.line)
    }
}

/// A binary body, little- or big-endian (`BIG`): values packed back to back.
struct BinaryBody<'a, const BIG: bool> {
    data: &'a [u8],
    pos: usize,
}

impl<'a, const BIG: bool> BinaryBody<'a, BIG> {
    fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }

    /// The next `N` bytes.
    #[inline(always)]
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let bytes = self.data.get(self.pos..self.pos + N)?;
        self.pos += N;
        bytes.try_into().ok()
    }
}

/// Decode a number of type `$t` from the body's next bytes in its byte order.
macro_rules! decode {
    ($body:expr, $t:ty) => {
        $body.take::<{ size_of::<$t>() }>().map(|b| {
            if BIG {
                <$t>::from_be_bytes(b) as f64
            } else {
                <$t>::from_le_bytes(b) as f64
            }
        })
    };
}

impl<const BIG: bool> Body for BinaryBody<'_, BIG> {
    fn begin(&mut self) -> Result<(), String> {
        Ok(())
    }

    #[inline]
    fn value(&mut self, ty: Scalar, what: &str) -> Result<f64, String> {
        let value = match ty {
            Scalar::I8 => decode!(self, i8),
            Scalar::U8 => decode!(self, u8),
            Scalar::I16 => decode!(self, i16),
            Scalar::U16 => decode!(self, u16),
            Scalar::I32 => decode!(self, i32),
            Scalar::U32 => decode!(self, u32),
            Scalar::F32 => decode!(self, f32),
            Scalar::F64 => decode!(self, f64),
        };
        value.ok_or_else(|| format!("unexpected end of data in `{what}` (truncated file?)"))
    }

    fn end(&mut self) -> Result<(), String> {
        Ok(())
    }

    fn finish(&mut self) -> Result<(), String> {
        let rest = &self.data[self.pos..];
        if rest.iter().all(u8::is_ascii_whitespace) {
            return Ok(());
        }
        Err(format!(
            "{} bytes of unexpected data after the last element (does the header count too few?)",
            rest.len()
        ))
    }

    fn line(&self) -> Option<usize> {
        None
    }
}
