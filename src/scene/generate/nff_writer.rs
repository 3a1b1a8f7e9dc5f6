//! Writing NFF text (the SPD's own output format, see `docs/nff.md`),
//! one entity at a time, straight to any [`Write`]. Numbers are printed like C's
//! `%g` (six significant digits), as the SPD programs print them, which keeps
//! the files as small as theirs and their coordinates identical.

use std::fmt;
use std::io::{self, Write};

use glam::DVec3;

/// The SPD's background colour, "UNC sky blue".
pub const SKY_BLUE: DVec3 = DVec3::new(0.078, 0.361, 0.753);

/// The camera of an NFF `v` entity. 96 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Eye position.
    pub from: DVec3,
    /// Look-at point.
    pub at: DVec3,
    /// Up direction.
    pub up: DVec3,
    /// Field of view in degrees, between the centres of the outer pixel rows.
    pub angle: f64,
    /// Distance of the near plane.
    pub hither: f64,
    /// Image size in pixels.
    pub resolution: [u32; 2],
}

impl View {
    /// The camera of most SPD generators: from `from` towards `at`, z up, a 45°
    /// view, hither 1, 512×512.
    pub fn looking_at(from: DVec3, at: DVec3) -> Self {
        Self {
            from,
            at,
            up: DVec3::Z,
            angle: 45.0,
            hither: 1.0,
            resolution: [512, 512],
        }
    }

    /// The SPD's usual camera: from `from` towards the origin, z up, a 45° view,
    /// hither 0.01, 512×512.
    pub fn towards_origin(from: DVec3) -> Self {
        Self {
            from,
            at: DVec3::ZERO,
            up: DVec3::Z,
            angle: 45.0,
            hither: 0.01,
            resolution: [512, 512],
        }
    }
}

/// The surface of an NFF `f` entity. 64 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Colour.
    pub color: DVec3,
    /// Diffuse weight.
    pub kd: f64,
    /// Specular (mirror) weight.
    pub ks: f64,
    /// Phong exponent, see [`phong_exponent`].
    pub shine: f64,
    /// Transmittance.
    pub transmittance: f64,
    /// Index of refraction.
    pub ior: f64,
}

impl Surface {
    /// A fully diffuse, opaque surface of `color` with no highlight.
    pub fn matte(color: DVec3) -> Self {
        Self {
            color,
            kd: 1.0,
            ks: 0.0,
            shine: phong_exponent(0.0),
            transmittance: 0.0,
            ior: 1.0,
        }
    }
}

/// The Phong exponent whose highlight falls to half strength `half_angle`
/// degrees off the mirror direction, the SPD's way of stating highlights:
/// `cos(θ)^n = ½`. A zero angle means no highlight (a huge exponent), one of
/// 90° or more a flat one (exponent 1). This is the exponent of the SPD files
/// raypack reproduces (balls' `3.0827` at 37°); the SPD 3.4 library takes
/// `cos(2θ)` instead (0.538 at 37°). Highlights change no ray counts.
pub fn phong_exponent(half_angle_deg: f64) -> f64 {
    let theta = half_angle_deg.to_radians();
    if theta <= 0.0 {
        100_000.0
    } else if theta >= std::f64::consts::FRAC_PI_2 {
        1.0
    } else {
        0.5f64.ln() / theta.cos().ln()
    }
}

/// Writes NFF entities and counts the primitives among them. 8 bytes plus the output.
#[derive(Debug)]
pub struct NffWriter<W: Write> {
    out: W,
    primitives: u64,
}

impl<W: Write> NffWriter<W> {
    /// A writer to `out` (wrap files in a `BufWriter`).
    pub fn new(out: W) -> Self {
        Self { out, primitives: 0 }
    }

    /// Comment lines, each prefixed with `# `.
    pub fn comment(&mut self, text: &str) -> io::Result<()> {
        for line in text.lines() {
            writeln!(self.out, "# {line}")?;
        }
        Ok(())
    }

    /// The camera (`v`).
    pub fn view(&mut self, v: &View) -> io::Result<()> {
        writeln!(self.out, "v")?;
        writeln!(self.out, "from {}", G3(v.from))?;
        writeln!(self.out, "at {}", G3(v.at))?;
        writeln!(self.out, "up {}", G3(v.up))?;
        writeln!(self.out, "angle {}", G(v.angle))?;
        writeln!(self.out, "hither {}", G(v.hither))?;
        writeln!(self.out, "resolution {} {}", v.resolution[0], v.resolution[1])
    }

    /// The background colour (`b`).
    pub fn background(&mut self, color: DVec3) -> io::Result<()> {
        writeln!(self.out, "b {}", G3(color))
    }

    /// A positional light (`l`).
    pub fn light(&mut self, position: DVec3) -> io::Result<()> {
        writeln!(self.out, "l {}", G3(position))
    }

    /// The surface of the primitives that follow (`f`).
    pub fn surface(&mut self, s: &Surface) -> io::Result<()> {
        writeln!(
            self.out,
            "f {} {} {} {} {} {}",
            G3(s.color),
            G(s.kd),
            G(s.ks),
            G(s.shine),
            G(s.transmittance),
            G(s.ior)
        )
    }

    /// A sphere (`s`).
    pub fn sphere(&mut self, center: DVec3, radius: f64) -> io::Result<()> {
        self.primitives += 1;
        writeln!(self.out, "s {} {}", G3(center), G(radius))
    }

    /// A polygon (`p`), vertices counter-clockwise seen from its front.
    pub fn polygon(&mut self, vertices: &[DVec3]) -> io::Result<()> {
        self.primitives += 1;
        writeln!(self.out, "p {}", vertices.len())?;
        for &v in vertices {
            writeln!(self.out, "{}", G3(v))?;
        }
        Ok(())
    }

    /// A polygonal patch (`pp`): a polygon with a shading normal at each
    /// vertex, written after it on the vertex's line.
    pub fn patch(&mut self, vertices: &[DVec3], normals: &[DVec3]) -> io::Result<()> {
        debug_assert_eq!(vertices.len(), normals.len());
        self.primitives += 1;
        writeln!(self.out, "pp {}", vertices.len())?;
        for (&v, &n) in vertices.iter().zip(normals) {
            writeln!(self.out, "{} {}", G3(v), G3(n))?;
        }
        Ok(())
    }

    /// A cone or cylinder without end caps (`c`): base centre and radius,
    /// then apex centre and radius, one line each.
    pub fn cone(&mut self, base: DVec3, base_radius: f64, apex: DVec3, apex_radius: f64) -> io::Result<()> {
        self.primitives += 1;
        writeln!(self.out, "c")?;
        writeln!(self.out, "{} {}", G3(base), G(base_radius))?;
        writeln!(self.out, "{} {}", G3(apex), G(apex_radius))
    }

    /// Primitives written so far.
    pub fn primitives(&self) -> u64 {
        self.primitives
    }

    /// Flush and return the output.
    pub fn finish(mut self) -> io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

/// A number printed like C's `%g`: six significant digits, trailing zeros
/// dropped, exponent form below 1e-4 and from 1e6 on; zero is always `0`.
#[derive(Clone, Copy, Debug)]
pub struct G(pub f64);

impl fmt::Display for G {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const DIGITS: i32 = 6;
        let v = self.0;
        if v == 0.0 {
            return f.write_str("0");
        }
        if !v.is_finite() {
            return write!(f, "{v}");
        }
        // The decimal exponent after rounding to six digits decides the form.
        let sci = format!("{:.*e}", (DIGITS - 1) as usize, v);
        let (mantissa, exp) = sci.split_once('e').expect("`{:e}` output has an exponent");
        let exp: i32 = exp.parse().expect("`{:e}` exponent is an integer");
        if (-4..DIGITS).contains(&exp) {
            let fixed = format!("{:.*}", (DIGITS - 1 - exp) as usize, v);
            f.write_str(trim_fraction(&fixed))
        } else {
            let sign = if exp < 0 { '-' } else { '+' };
            write!(f, "{}e{sign}{:02}", trim_fraction(mantissa), exp.abs())
        }
    }
}

/// Three numbers separated by spaces.
struct G3(DVec3);

impl fmt::Display for G3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {} {}", G(self.0.x), G(self.0.y), G(self.0.z))
    }
}

/// `digits` without trailing zeros after a decimal point (and without the point
/// if nothing follows it).
fn trim_fraction(digits: &str) -> &str {
    if digits.contains('.') {
        digits.trim_end_matches('0').trim_end_matches('.')
    } else {
        digits
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_like_c_percent_g() {
        let cases = [
            (0.0, "0"),
            (-0.0, "0"),
            (1.0, "1"),
            (-12.0, "-12"),
            (0.5, "0.5"),
            (1.0 / 3.0, "0.333333"),
            (0.272_165_526_975_908_7, "0.272166"),
            (100_000.0, "100000"),
            (1_234_567.0, "1.23457e+06"),
            (999_999.5, "1e+06"),
            (0.000_123_456_7, "0.000123457"),
            (0.000_012_345, "1.2345e-05"),
            (3.082_693_5, "3.08269"),
            (9.999_996, "10"),
        ];
        for (v, want) in cases {
            assert_eq!(G(v).to_string(), want, "{v:e}");
        }
    }

    #[test]
    fn phong_exponent_halves_the_highlight_at_the_angle() {
        let n = phong_exponent(37.0);
        assert!((37f64.to_radians().cos().powf(n) - 0.5).abs() < 1e-12);
        assert_eq!(G(n).to_string(), "3.0827", "as in the published balls.nff");
        assert_eq!(phong_exponent(0.0), 100_000.0);
        assert_eq!(phong_exponent(90.0), 1.0);
    }

    #[test]
    fn entities_are_written_and_primitives_counted() {
        let mut w = NffWriter::new(Vec::new());
        w.comment("two\nlines").unwrap();
        w.sphere(DVec3::new(1.0, 2.0, 3.0), 0.5).unwrap();
        w.polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]).unwrap();
        w.patch(&[DVec3::ZERO, DVec3::X, DVec3::Y], &[DVec3::Z; 3])
            .unwrap();
        w.cone(DVec3::ZERO, 0.5, DVec3::Z, 0.25).unwrap();
        assert_eq!(w.primitives(), 4);
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        assert_eq!(
            text,
            "# two\n# lines\ns 1 2 3 0.5\np 3\n0 0 0\n1 0 0\n0 1 0\n\
             pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n\
             c\n0 0 0 0.5\n0 0 1 0.25\n"
        );
    }
}
