//! The plain CSV files that let any engine be compared with raypack.
//!
//! Rays: a header `ox,oy,oz,dx,dy,dz,tmin,tmax`, then one ray per line; blank
//! lines are skipped; numbers are anything Rust's `f32` parser takes (`inf`
//! included). Directions are normalised on reading, so `t` is a distance.
//!
//! Hits: a header `t,prim`, then one line per ray in the same order: the hit's
//! `t` (shortest text that reads back to the same f32) and the primitive's index
//! in file order, or `inf,-1` for a miss.

use std::fmt::Write as _;
use std::path::Path;

use crate::ray::{Hit, NO_HIT, Ray};

/// The rays file's header.
pub const RAYS_HEADER: &str = "ox,oy,oz,dx,dy,dz,tmin,tmax";
/// The hits file's header.
pub const HITS_HEADER: &str = "t,prim";

/// A rays file that cannot be read: where and what was expected.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvError {
    /// The file.
    pub path: String,
    /// 1-based line number; None when the file itself cannot be read.
    pub line: Option<usize>,
    /// What was wrong or expected.
    pub message: String,
}

impl std::fmt::Display for CsvError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.path, line, self.message),
            None => write!(f, "{}: {}", self.path, self.message),
        }
    }
}

impl std::error::Error for CsvError {}

/// The error at a line of the file `path`.
fn line_error(path: &str) -> impl Fn(usize, String) -> CsvError + '_ {
    move |line, message| CsvError {
        path: path.to_string(),
        line: Some(line),
        message,
    }
}

/// The numbered non-blank lines of `text` after its first one, which must be
/// `header` (spaces ignored); else the line and what was expected.
fn data_lines<'a>(
    text: &'a str,
    header: &str,
) -> Result<impl Iterator<Item = (usize, &'a str)>, (usize, String)> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    match lines.next() {
        Some((_, first)) if first.replace(' ', "") == header => Ok(lines),
        Some((n, other)) => Err((n, format!("expected the header `{header}`, got `{other}`"))),
        None => Err((1, format!("empty file: expected the header `{header}`"))),
    }
}

/// Parse the text of a rays file; `path` names it in errors.
pub fn parse_rays(path: &str, text: &str) -> Result<Vec<Ray>, CsvError> {
    let error = line_error(path);
    let lines = data_lines(text, RAYS_HEADER).map_err(|(n, message)| error(n, message))?;
    let mut rays = Vec::new();
    for (n, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != 8 {
            return Err(error(
                n,
                format!("expected 8 numbers ({RAYS_HEADER}), got {} fields", fields.len()),
            ));
        }
        let mut v = [0.0f32; 8];
        for (k, (slot, field)) in v.iter_mut().zip(&fields).enumerate() {
            *slot = field.parse().map_err(|_| {
                let name = RAYS_HEADER.split(',').nth(k).unwrap_or("?");
                error(n, format!("{name}: expected a number, got `{field}`"))
            })?;
        }
        let [ox, oy, oz, dx, dy, dz, tmin, tmax] = v;
        let origin = glam::Vec3::new(ox, oy, oz);
        if !origin.is_finite() {
            return Err(error(n, "the origin must be finite".into()));
        }
        let Some(dir) = glam::Vec3::new(dx, dy, dz).try_normalize() else {
            return Err(error(n, "the direction must be finite and non-zero".into()));
        };
        if tmin.is_nan() || tmax.is_nan() || tmin > tmax {
            return Err(error(n, format!("expected tmin <= tmax, got {tmin} and {tmax}")));
        }
        rays.push(Ray::new(origin, dir, tmin, tmax));
    }
    Ok(rays)
}

/// Read the file at `path` and parse it with `parse` (which names it in errors).
fn read_with<T>(path: &Path, parse: fn(&str, &str) -> Result<T, CsvError>) -> Result<T, CsvError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| CsvError {
        path: name.clone(),
        line: None,
        message: format!("cannot read: {e}"),
    })?;
    parse(&name, &text)
}

/// Read a rays file.
pub fn read_rays(path: &Path) -> Result<Vec<Ray>, CsvError> {
    read_with(path, parse_rays)
}

/// Parse the text of a hits file (what [`format_hits`] writes, `inf,-1` for a
/// miss); `path` names it in errors.
pub fn parse_hits(path: &str, text: &str) -> Result<Vec<Hit>, CsvError> {
    let error = line_error(path);
    let lines = data_lines(text, HITS_HEADER).map_err(|(n, message)| error(n, message))?;
    let mut hits = Vec::new();
    for (n, line) in lines {
        let (t, prim) = line
            .split_once(',')
            .ok_or_else(|| error(n, format!("expected `t,prim`, got `{line}`")))?;
        let t: f32 = t
            .trim()
            .parse()
            .map_err(|_| error(n, format!("t: expected a number, got `{t}`")))?;
        let prim: i64 = prim
            .trim()
            .parse()
            .map_err(|_| error(n, format!("prim: expected an integer, got `{prim}`")))?;
        let record = |t: f32, prim: u32| Hit {
            t,
            prim,
            u: 0.0,
            v: 0.0,
            ng: glam::Vec3::ZERO,
        };
        let hit = match (prim, t) {
            (-1, t) if t == f32::INFINITY => record(t, NO_HIT),
            (-1, _) => return Err(error(n, format!("a miss is `inf,-1`, got t = {t}"))),
            (p, t) if (0..i64::from(NO_HIT)).contains(&p) && t.is_finite() => record(t, p as u32),
            _ => {
                return Err(error(
                    n,
                    format!("expected a finite t and a primitive index, got `{line}`"),
                ));
            }
        };
        hits.push(hit);
    }
    Ok(hits)
}

/// Read a hits file.
pub fn read_hits(path: &Path) -> Result<Vec<Hit>, CsvError> {
    read_with(path, parse_hits)
}

/// The text of a rays file.
pub fn format_rays(rays: &[Ray]) -> String {
    let mut out = format!("{RAYS_HEADER}\n");
    for r in rays {
        let (o, d) = (r.origin, r.dir);
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{}",
            o.x, o.y, o.z, d.x, d.y, d.z, r.t_min, r.t_max
        );
    }
    out
}

/// The text of a hits file.
pub fn format_hits(hits: &[Hit]) -> String {
    let mut out = format!("{HITS_HEADER}\n");
    for h in hits {
        let _ = if h.is_hit() {
            writeln!(out, "{},{}", h.t, h.prim)
        } else {
            writeln!(out, "inf,-1")
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn rays_round_trip_through_the_text_format() {
        let rays = vec![
            Ray::new(
                Vec3::new(0.1, -2.5, 3.0),
                Vec3::new(0.0, 0.6, 0.8),
                1e-4,
                f32::INFINITY,
            ),
            Ray::new(Vec3::new(1e-30, 7.0, -0.333_333_34), Vec3::X, 0.0, 12.5),
        ];
        assert_eq!(parse_rays("r.csv", &format_rays(&rays)).unwrap(), rays);
    }

    #[test]
    fn directions_are_normalised_and_blank_lines_skipped() {
        let text = "\n ox, oy, oz, dx, dy, dz, tmin, tmax\n0,0,0, 0,0,2, 0,inf\n\n1,1,1,3,0,4,0.5,9\n";
        let rays = parse_rays("r.csv", text).unwrap();
        assert_eq!(rays.len(), 2);
        assert_eq!(rays[0].dir, Vec3::Z);
        assert_eq!(rays[1].dir, Vec3::new(0.6, 0.0, 0.8));
        assert_eq!((rays[1].t_min, rays[1].t_max), (0.5, 9.0));
    }

    #[test]
    fn bad_rays_files_say_where_and_what() {
        let cases = [
            ("", "r.csv:1: empty file"),
            ("x,y\n", "r.csv:1: expected the header"),
            (
                concat!("ox,oy,oz,dx,dy,dz,tmin,tmax\n", "0,0,0,1,0,0,0\n"),
                "r.csv:2: expected 8 numbers",
            ),
            (
                concat!(
                    "ox,oy,oz,dx,dy,dz,tmin,tmax\n",
                    "0,0,0,1,0,0,0,inf\n0,zero,0,1,0,0,0,1\n"
                ),
                "r.csv:3: oy: expected a number, got `zero`",
            ),
            (
                concat!("ox,oy,oz,dx,dy,dz,tmin,tmax\n", "0,0,0,0,0,0,0,1\n"),
                "r.csv:2: the direction must be finite",
            ),
            (
                concat!("ox,oy,oz,dx,dy,dz,tmin,tmax\n", "nan,0,0,1,0,0,0,1\n"),
                "r.csv:2: the origin must be finite",
            ),
            (
                concat!("ox,oy,oz,dx,dy,dz,tmin,tmax\n", "0,0,0,1,0,0,2,1\n"),
                "r.csv:2: expected tmin <= tmax",
            ),
        ];
        for (text, expected) in cases {
            let e = parse_rays("r.csv", text).unwrap_err().to_string();
            assert!(e.starts_with(expected), "{e:?} should start with {expected:?}");
        }
    }

    #[test]
    fn hits_are_written_with_exact_t_and_misses_as_inf_minus_one() {
        let ray = Ray::unbounded(Vec3::ZERO, Vec3::Z);
        let mut hit = Hit::none(&ray);
        hit.record(0.1 + 0.2, 7, 0.0, 0.0);
        let text = format_hits(&[hit, Hit::none(&ray)]);
        assert_eq!(text, "t,prim\n0.3,7\ninf,-1\n");
        let t: f32 = text
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert_eq!(t.to_bits(), (0.1f32 + 0.2f32).to_bits());
        // And back, bit for bit.
        let back = parse_hits("h.csv", &text).unwrap();
        assert_eq!((back[0].t.to_bits(), back[0].prim), (hit.t.to_bits(), 7));
        assert!(!back[1].is_hit() && back[1].t == f32::INFINITY);
    }

    #[test]
    fn bad_hits_files_name_the_line_and_what_was_expected() {
        for (text, says) in [
            ("", "h.csv:1: empty file: expected the header `t,prim`"),
            ("t,id\n", "h.csv:1: expected the header `t,prim`, got `t,id`"),
            ("t,prim\n0.5\n", "h.csv:2: expected `t,prim`, got `0.5`"),
            ("t,prim\n\nx,3\n", "h.csv:3: t: expected a number, got `x`"),
            (
                "t,prim\n0.5,-2\n",
                "h.csv:2: expected a finite t and a primitive index, got `0.5,-2`",
            ),
            ("t,prim\n0.5,-1\n", "h.csv:2: a miss is `inf,-1`, got t = 0.5"),
            (
                "t,prim\nnan,1\n",
                "h.csv:2: expected a finite t and a primitive index, got `nan,1`",
            ),
            ("t,prim\n1,2.5\n", "h.csv:2: prim: expected an integer, got `2.5`"),
        ] {
            assert_eq!(parse_hits("h.csv", text).unwrap_err().to_string(), says);
        }
    }
}
