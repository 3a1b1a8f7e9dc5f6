//! A double-precision ray/triangle reference, written for the robustness
//! oracle apart from the engine's kernels: the f32 inputs (exact in f64),
//! the signed volumes of the ray against each edge (the orientation of the
//! ray's line to each edge, Plücker's test in its triple-product form), and
//! the plane distance `⟨n, a − o⟩ / ⟨n, d⟩`. Where an edge's volume is
//! within a relative [`AMBIGUOUS`] of zero the ray passes so close to that
//! edge that an f32 engine may go either way: the reference says so rather
//! than pick a side.

use glam::{DVec3, Vec3};

use crate::ray::{NO_HIT, Ray};

/// Relative size of an edge volume, against the product of its three
/// vectors' lengths, below which a ray is on the edge as far as f32
/// arithmetic can tell (a few hundred f32 ulps).
pub const AMBIGUOUS: f64 = 3e-5;

/// The reference's answer for one ray against one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TriangleAnswer {
    /// Clearly outside an edge, parallel, or outside `[t_min, t_max]`.
    Miss,
    /// Clearly inside, at this t.
    Hit(f64),
    /// Within [`AMBIGUOUS`] of an edge or vertex, at this t (of the plane).
    Edge(f64),
}

/// Triangle `a, b, c` against `ray`, in f64.
pub fn intersect_triangle(a: Vec3, b: Vec3, c: Vec3, ray: &Ray) -> TriangleAnswer {
    let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
    let (pa, pb, pc) = (a.as_dvec3() - o, b.as_dvec3() - o, c.as_dvec3() - o);
    // The signed volume of the ray's direction against each edge, and how
    // small it is relative to its factors.
    let volume = |p: DVec3, q: DVec3| {
        let v = d.dot(p.cross(q));
        let size = d.length() * p.length() * q.length();
        (v, v.abs() <= AMBIGUOUS * size)
    };
    let edges = [volume(pa, pb), volume(pb, pc), volume(pc, pa)];
    let n = (b - a).as_dvec3().cross((c - a).as_dvec3());
    let denom = n.dot(d);
    if denom == 0.0 || !denom.is_finite() {
        return TriangleAnswer::Miss;
    }
    let t = n.dot(pa) / denom;
    if !(t >= f64::from(ray.t_min) && t <= f64::from(ray.t_max)) {
        return TriangleAnswer::Miss;
    }
    let near_edge = edges.iter().any(|&(_, near)| near);
    let clear = edges.iter().filter(|&&(_, near)| !near);
    let positive = clear.clone().any(|&(v, _)| v > 0.0);
    let negative = clear.clone().any(|&(v, _)| v < 0.0);
    match (positive && negative, near_edge) {
        (true, _) => TriangleAnswer::Miss,
        (false, false) => TriangleAnswer::Hit(t),
        (false, true) => TriangleAnswer::Edge(t),
    }
}

/// The reference's nearest hit of a ray among triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// The nearest t of any triangle hit or on whose edge the ray runs, and
    /// that triangle's index ([`NO_HIT`] if none).
    pub t: f64,
    /// See `t`.
    pub prim: u32,
    /// True when no triangle is hit for certain nearer than (or as near as)
    /// an ambiguous one: whether the ray hits, or which triangle it hits
    /// first, f32 arithmetic may decide either way.
    pub ambiguous: bool,
    /// True when some triangle is hit for certain.
    pub surely_hit: bool,
}

/// The nearest hit of `ray` among `triangles` (brute force).
pub fn nearest(triangles: &[[Vec3; 3]], ray: &Ray) -> Nearest {
    let (mut sure, mut edge) = ((f64::INFINITY, NO_HIT), (f64::INFINITY, NO_HIT));
    for (i, [a, b, c]) in triangles.iter().enumerate() {
        match intersect_triangle(*a, *b, *c, ray) {
            TriangleAnswer::Miss => {}
            TriangleAnswer::Hit(t) if t < sure.0 => sure = (t, i as u32),
            TriangleAnswer::Edge(t) if t < edge.0 => edge = (t, i as u32),
            _ => {}
        }
    }
    // An edge nearer than the sure hit, or level with it (within f32's
    // reach), leaves the first hit open.
    let level = |x: f64| x.abs() * 1e-6;
    let ambiguous = edge.1 != NO_HIT && edge.0 <= sure.0 + level(sure.0);
    let (t, prim) = if edge.0 < sure.0 { edge } else { sure };
    Nearest {
        t,
        prim,
        ambiguous,
        surely_hit: sure.1 != NO_HIT,
    }
}

/// The t at which `ray`'s line meets the plane of triangle `a, b, c`, in f64.
pub fn plane_t(a: Vec3, b: Vec3, c: Vec3, ray: &Ray) -> f64 {
    let n = (b - a).as_dvec3().cross((c - a).as_dvec3());
    n.dot(a.as_dvec3() - ray.origin.as_dvec3()) / n.dot(ray.dir.as_dvec3())
}

/// How many f32 ulps the engine's `t` is from `reference`, the ulps taken at
/// `scale` or at `reference`, whichever is larger: where the origin's
/// coordinates are much larger than t (a secondary ray), the hit point
/// carries their rounding, not t's.
pub fn ulps_from(t: f32, reference: f64, scale: f32) -> f64 {
    let r = (reference.abs() as f32).max(scale.abs());
    let ulp = (f32::from_bits(r.to_bits() + 1) - r) as f64;
    (f64::from(t) - reference).abs() / ulp
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::unbounded(Vec3::from(o), Vec3::from(d))
    }

    #[test]
    fn inside_edge_and_outside_are_told_apart() {
        let (a, b, c) = (
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        );
        assert_eq!(
            intersect_triangle(a, b, c, &ray([0.25, 0.25, 0.0], [0.0, 0.0, 1.0])),
            TriangleAnswer::Hit(2.0)
        );
        assert_eq!(
            intersect_triangle(a, b, c, &ray([0.5, 0.0, 0.0], [0.0, 0.0, 1.0])),
            TriangleAnswer::Edge(2.0)
        );
        assert_eq!(
            intersect_triangle(a, b, c, &ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])),
            TriangleAnswer::Edge(2.0)
        );
        assert_eq!(
            intersect_triangle(a, b, c, &ray([0.6, 0.6, 0.0], [0.0, 0.0, 1.0])),
            TriangleAnswer::Miss
        );
        // Behind, parallel.
        assert_eq!(
            intersect_triangle(a, b, c, &ray([0.25, 0.25, 3.0], [0.0, 0.0, 1.0])),
            TriangleAnswer::Miss
        );
        assert_eq!(
            intersect_triangle(a, b, c, &ray([0.25, 0.25, 0.0], [1.0, 0.0, 0.0])),
            TriangleAnswer::Miss
        );
    }

    #[test]
    fn the_nearest_is_open_where_an_edge_is_as_near() {
        let quad = [
            [
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::new(1.0, 0.0, 2.0),
                Vec3::new(1.0, 1.0, 2.0),
            ],
            [
                Vec3::new(0.0, 0.0, 2.0),
                Vec3::new(1.0, 1.0, 2.0),
                Vec3::new(0.0, 1.0, 2.0),
            ],
            [
                Vec3::new(-5.0, -5.0, 3.0),
                Vec3::new(5.0, -5.0, 3.0),
                Vec3::new(0.0, 5.0, 3.0),
            ],
        ];
        let diagonal = nearest(&quad, &ray([0.5, 0.5, 0.0], [0.0, 0.0, 1.0]));
        assert!(diagonal.ambiguous && diagonal.surely_hit && diagonal.t == 2.0);
        let clear = nearest(&quad, &ray([0.7, 0.2, 0.0], [0.0, 0.0, 1.0]));
        assert_eq!((clear.t, clear.prim, clear.ambiguous), (2.0, 0, false));
        assert_eq!(ulps_from(2.0, 2.0, 0.0), 0.0);
        assert!((ulps_from(f32::from_bits(2f32.to_bits() + 3), 2.0, 1.0) - 3.0).abs() < 1e-9);
        // At a larger scale, the same difference is fewer ulps.
        assert!((ulps_from(f32::from_bits(2f32.to_bits() + 4), 2.0, 4.0) - 2.0).abs() < 1e-9);
        let r = ray([0.25, 0.25, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(plane_t(quad[2][0], quad[2][1], quad[2][2], &r), 3.0);
    }
}
