//! Ear clipping: split a simple planar polygon, convex or concave, into triangles,
//! for engines that take triangles only (Embree, exporters).
//!
//! The polygon is projected onto the coordinate plane that drops its normal's
//! dominant axis (as the crossing test of [`Polygon`](super::Polygon) does) and
//! worked on in f64. A simple polygon of n ≥ 4 vertices always has an *ear*: a
//! convex vertex `b` whose triangle `(a, b, c)` with its two neighbours holds no
//! other vertex (G. H. Meisters, "Polygons have ears", Amer. Math. Monthly 82(6),
//! 1975). Cutting it off leaves a simple polygon of n − 1 vertices; repeating
//! gives the n − 2 triangles in O(n³) worst case, which is fine for the polygon
//! sizes of scene files (the SPD gears have 144-vertex faces).
//!
//! Vertices that repeat their predecessor or lie on the line through their
//! neighbours add no area and are dropped without a triangle. A polygon with no
//! ear left, or whose edges cross or touch (checked up front, O(n²)), is not
//! simple and is refused: ear clipping would cover a different region than the
//! even-odd crossing test.

use glam::{DVec2, Vec3};

/// Why a polygon cannot be ear-clipped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum EarClipError {
    /// Fewer than three vertices.
    #[error("polygon needs at least 3 vertices, got {0}")]
    TooFewVertices(usize),
    /// The polygon's edges cross or touch each other, or no ear is left.
    #[error("polygon is not simple (its edges cross or touch)")]
    NotSimple,
}

/// Twice the signed area of the 2D triangle `a, b, c` (> 0 when counter-clockwise).
#[inline]
fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Whether `p` lies inside or on the boundary of the counter-clockwise (after
/// multiplying by `sign`) triangle `a, b, c`.
#[inline]
fn in_triangle(p: DVec2, [a, b, c]: [DVec2; 3], sign: f64) -> bool {
    orient(a, b, p) * sign >= 0.0 && orient(b, c, p) * sign >= 0.0 && orient(c, a, p) * sign >= 0.0
}

/// Whether the closed 2D segments `p–q` and `r–s` share a point.
fn segments_touch(p: DVec2, q: DVec2, r: DVec2, s: DVec2) -> bool {
    let (d1, d2) = (orient(p, q, r), orient(p, q, s));
    let (d3, d4) = (orient(r, s, p), orient(r, s, q));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return true; // proper crossing
    }
    // Touching or collinear overlap: an endpoint on the other segment.
    let on =
        |a: DVec2, b: DVec2, p: DVec2, d: f64| d == 0.0 && p.cmpge(a.min(b)).all() && p.cmple(a.max(b)).all();
    on(p, q, r, d1) || on(p, q, s, d2) || on(r, s, p, d3) || on(r, s, q, d4)
}

/// Whether two edges of the ring that are not neighbours share a point.
fn edges_cross(points: &[DVec2], ring: &[usize]) -> bool {
    let m = ring.len();
    let edge = |i: usize| (points[ring[i]], points[ring[(i + 1) % m]]);
    (0..m).any(|i| {
        ((i + 2)..m).filter(|&j| (j + 1) % m != i).any(|j| {
            let ((p, q), (r, s)) = (edge(i), edge(j));
            segments_touch(p, q, r, s)
        })
    })
}

/// Triangulate the polygon `vertices` (in order, planar, with unit or non-unit
/// normal `normal`) into triangles of indices into `vertices`. Every triangle keeps
/// the polygon's winding; zero-area pieces are left out, so a polygon with
/// collinear or repeated vertices yields fewer than `n − 2` triangles.
pub fn ear_clip(vertices: &[Vec3], normal: Vec3) -> Result<Vec<[u32; 3]>, EarClipError> {
    if vertices.len() < 3 {
        return Err(EarClipError::TooFewVertices(vertices.len()));
    }
    // Step 1: project onto the plane of the two non-dominant axes of the normal.
    let abs = normal.abs();
    let k = if abs.x >= abs.y && abs.x >= abs.z {
        0
    } else if abs.y >= abs.z {
        1
    } else {
        2
    };
    let (ku, kv) = ((k + 1) % 3, (k + 2) % 3);
    let points: Vec<DVec2> = vertices
        .iter()
        .map(|v| DVec2::new(v[ku] as f64, v[kv] as f64))
        .collect();

    // Step 2: the ring of remaining vertices, without consecutive repeats.
    let mut ring: Vec<usize> = Vec::with_capacity(points.len());
    for i in 0..points.len() {
        if ring.last().is_none_or(|&last| points[last] != points[i]) {
            ring.push(i);
        }
    }
    while ring.len() > 1 && points[ring[0]] == points[*ring.last().unwrap_or(&0)] {
        ring.pop();
    }

    if edges_cross(&points, &ring) {
        return Err(EarClipError::NotSimple);
    }

    // Step 3: the orientation of the projected polygon (shoelace formula), so
    // "convex" means turning the way the polygon turns, whichever way it is wound.
    let area2: f64 = (0..ring.len())
        .map(|i| points[ring[i]].perp_dot(points[ring[(i + 1) % ring.len()]]))
        .sum();
    let sign = if area2 < 0.0 { -1.0 } else { 1.0 };

    // Step 4: cut ears until a triangle is left.
    let mut triangles = Vec::with_capacity(ring.len().saturating_sub(2));
    let mut j = 0;
    while ring.len() > 3 {
        let m = ring.len();
        let mut clipped = false;
        for step in 0..m {
            let at = (j + step) % m;
            let (ia, ib, ic) = (ring[(at + m - 1) % m], ring[at], ring[(at + 1) % m]);
            let tri = [points[ia], points[ib], points[ic]];
            let turn = orient(tri[0], tri[1], tri[2]) * sign;
            if turn < 0.0 {
                continue; // reflex vertex: not an ear
            }
            if turn > 0.0 {
                // A convex vertex is an ear when no other vertex lies in its triangle.
                let blocked = ring.iter().any(|&i| {
                    i != ia
                        && i != ib
                        && i != ic
                        && !tri.contains(&points[i])
                        && in_triangle(points[i], tri, sign)
                });
                if blocked {
                    continue;
                }
                triangles.push([ia as u32, ib as u32, ic as u32]);
            }
            // Zero turn: a straight or spike vertex adds no area; drop it silently.
            ring.remove(at);
            j = at % ring.len();
            clipped = true;
            break;
        }
        if !clipped {
            return Err(EarClipError::NotSimple);
        }
    }
    if ring.len() == 3 && orient(points[ring[0]], points[ring[1]], points[ring[2]]) != 0.0 {
        triangles.push([ring[0] as u32, ring[1] as u32, ring[2] as u32]);
    }
    Ok(triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Intersect, Polygon, Triangle};
    use crate::ray::{Hit, Ray};
    use crate::rng::Rng;

    /// Twice the signed area of a 2D polygon in the xy plane.
    fn area2_xy(points: &[Vec3]) -> f64 {
        (0..points.len())
            .map(|i| {
                let (a, b) = (points[i], points[(i + 1) % points.len()]);
                a.x as f64 * b.y as f64 - b.x as f64 * a.y as f64
            })
            .sum()
    }

    fn tri_area2_xy(points: &[Vec3], [a, b, c]: [u32; 3]) -> f64 {
        area2_xy(&[points[a as usize], points[b as usize], points[c as usize]])
    }

    /// A gear outline like the SPD `gears` faces: `teeth` teeth of 4 vertices each.
    fn gear(teeth: usize) -> Vec<Vec3> {
        (0..4 * teeth)
            .map(|i| {
                let r = if (i / 2) % 2 == 0 { 1.0 } else { 0.8 };
                let a = i as f32 * std::f32::consts::TAU / (4 * teeth) as f32;
                Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect()
    }

    fn star(points: usize) -> Vec<Vec3> {
        (0..2 * points)
            .map(|i| {
                let r = if i % 2 == 0 { 1.0 } else { 0.35 };
                let a = i as f32 * std::f32::consts::PI / points as f32;
                Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect()
    }

    /// A comb: a base bar with `teeth` thin upward teeth, counter-clockwise; deeply
    /// concave, with few ears.
    fn comb(teeth: usize) -> Vec<Vec3> {
        let mut v = vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(teeth as f32, 0.0, 0.0)];
        for t in (0..teeth).rev() {
            let x = t as f32;
            v.extend([
                Vec3::new(x + 0.6, 1.0, 0.0),
                Vec3::new(x + 0.6, 3.0, 0.0),
                Vec3::new(x + 0.2, 3.0, 0.0),
                Vec3::new(x + 0.2, 1.0, 0.0),
            ]);
        }
        v
    }

    fn check_cover(points: &[Vec3]) {
        let tris = ear_clip(points, Vec3::Z).expect("simple polygon");
        // n − 2 triangles, less the zero-area ones that collinear runs would give.
        assert!(tris.len() <= points.len() - 2 && tris.len() >= points.len() / 3);
        let total: f64 = tris.iter().map(|&t| tri_area2_xy(points, t)).sum();
        let area = area2_xy(points);
        assert!(
            (total - area).abs() <= 1e-9 * area.abs().max(1.0),
            "{total} vs {area}"
        );
        for &t in &tris {
            // Same winding as the polygon, never inverted.
            assert!(tri_area2_xy(points, t) * area.signum() > 0.0, "{t:?}");
        }
    }

    #[test]
    fn triangles_cover_convex_and_concave_polygons_with_their_winding() {
        let square = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        check_cover(&square);
        let clockwise: Vec<Vec3> = square.iter().rev().copied().collect();
        check_cover(&clockwise);
        check_cover(&star(5));
        check_cover(&star(12));
        check_cover(&gear(36)); // 144 vertices, like the SPD gears
        check_cover(&comb(6));
        let reversed_comb: Vec<Vec3> = comb(6).into_iter().rev().collect();
        check_cover(&reversed_comb);
    }

    #[test]
    fn repeated_and_collinear_vertices_add_no_triangles() {
        let p = vec![
            Vec3::ZERO,
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::X,
            Vec3::X,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::Y,
            Vec3::ZERO,
        ];
        let tris = ear_clip(&p, Vec3::Z).unwrap();
        assert_eq!(tris.len(), 3, "5 distinct vertices");
        let total: f64 = tris.iter().map(|&t| tri_area2_xy(&p, t)).sum();
        assert!((total - 2.0).abs() < 1e-12);
        assert!(
            tris.iter().all(|&t| tri_area2_xy(&p, t) > 0.0),
            "no zero-area triangle"
        );
        // Entirely collinear: no area, no triangles, no error.
        let line = vec![Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)];
        assert!(ear_clip(&line, Vec3::Z).unwrap().is_empty());
    }

    #[test]
    fn crossing_edges_and_short_inputs_are_refused() {
        let bowtie = vec![Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::X, Vec3::Y];
        assert_eq!(ear_clip(&bowtie, Vec3::Z), Err(EarClipError::NotSimple));
        // A pentagram drawn with crossing edges (vertex order 0, 2, 4, 1, 3).
        let pentagram: Vec<Vec3> = (0..5)
            .map(|i| {
                let a = (2 * i) as f32 * std::f32::consts::TAU / 5.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        assert_eq!(ear_clip(&pentagram, Vec3::Z), Err(EarClipError::NotSimple));
        assert_eq!(
            ear_clip(&[Vec3::ZERO, Vec3::X], Vec3::Z),
            Err(EarClipError::TooFewVertices(2))
        );
    }

    /// Random rays hit the polygon (crossing test) exactly where they hit one of
    /// its triangles (projected barycentric test); the two may differ only for
    /// rays that pass within a hair of the outline.
    #[test]
    fn triangles_hit_where_the_polygon_is_hit() {
        let tilt = |v: Vec3| Vec3::new(v.x, v.y, 0.3 * v.x - 0.2 * v.y + 1.0);
        for outline in [star(7), gear(36), comb(5)] {
            let vertices: Vec<Vec3> = outline.iter().map(|&v| tilt(v)).collect();
            let polygon = Polygon::new(&vertices).unwrap();
            let tris: Vec<Triangle> = ear_clip(&vertices, polygon.normal())
                .unwrap()
                .iter()
                .map(|t| {
                    Triangle::new(
                        vertices[t[0] as usize],
                        vertices[t[1] as usize],
                        vertices[t[2] as usize],
                    )
                })
                .collect();
            let b = polygon.bounds();
            let mut rng = Rng::new(7);
            let mut disagreements = 0;
            let n = 200_000;
            for _ in 0..n {
                let aim = rng.point_in(b.min - 0.1, b.max + 0.1);
                let origin = aim + 5.0 * rng.unit_vector();
                let ray = Ray::unbounded(origin, (aim - origin).normalize());
                let poly_hit = polygon.intersect(&ray, 0, &mut Hit::none(&ray));
                let mut hit = Hit::none(&ray);
                let tri_hit = tris.iter().any(|t| t.intersect(&ray, 0, &mut hit));
                if poly_hit != tri_hit {
                    // Only at the outline: distance to the nearest edge, in the plane's xy.
                    let t = (polygon.plane_offset() - polygon.normal().dot(ray.origin))
                        / polygon.normal().dot(ray.dir);
                    let p = ray.at(t);
                    let d = (0..vertices.len())
                        .map(|i| {
                            let (a, c) = (vertices[i], vertices[(i + 1) % vertices.len()]);
                            let ab = (c - a).truncate();
                            let s = ((p - a).truncate().dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
                            ((p - a).truncate() - s * ab).length()
                        })
                        .fold(f32::INFINITY, f32::min);
                    assert!(d < 1e-5, "disagreement {d} away from the outline");
                    disagreements += 1;
                }
            }
            assert!(disagreements * 10_000 <= n, "{disagreements} disagreements");
        }
    }
}
