//! Planar polygon, convex or concave, any vertex count (lecture section 6):
//! intersect the polygon's plane, project the hit onto the coordinate plane that
//! drops the normal's dominant axis, and count how often a 2D ray from the point
//! in direction (1, 0) crosses the edges; odd means inside.
//!
//! An edge `d_i → d_{i+1}` is crossed when the point's y lies in the half-open
//! span `[min(y_i, y_{i+1}), max(y_i, y_{i+1}))` (the lecture's `s ∈ [0, 1]`,
//! half-open so a vertex shared by two edges counts once) and the crossing
//! `x_i + (y − y_i)·(x_{i+1} − x_i)/(y_{i+1} − y_i)` lies to the right of the point.
//! Horizontal edges can never be crossed and are dropped when the polygon is built.
//!
//! That is the kernel under [`TriangleTest::Barycentric`] (the lecture's
//! kernels). Under [`TriangleTest::Watertight`], the default, a polygon is
//! tested as its surface cut into triangles (ear clipping on its plane,
//! [`Polygon::triangles`]), each under the watertight test: no ray passes
//! between the pieces, nor between the polygon and a neighbour that shares an
//! edge, and a BVH stores the pieces in its triangle blocks, 8 tested in one
//! pass with tight boxes, where the crossing test walks every edge of the
//! polygon (144 on an SPD gear's face). A hit names the polygon either way;
//! its `u, v` are 0 under the crossing test, and the barycentrics within the
//! piece hit under the pieces.

use glam::Vec3;

use crate::bounds::Aabb;
use crate::geometry::ear_clip::{EarClipError, ear_clip};
use crate::geometry::triangle_watertight::{ShearedRay, WatertightTriangle};
use crate::geometry::{
    GeometryError, Intersect, Triangle, TriangleTest, usable_denominator, usable_denominators,
};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::simd::SimdFloat;

/// One non-horizontal edge in the projection plane, with its inverse slope
/// precomputed so the crossing test needs no division. 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Edge {
    x0: f32,
    y0: f32,
    y1: f32,
    /// `(x1 − x0) / (y1 − y0)`.
    dx_dy: f32,
}

/// A planar polygon. 104 bytes, plus 16 bytes per non-horizontal edge, 12 per
/// vertex and 36 per watertight piece.
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    /// Unit normal, fixed by the first three vertices (counter-clockwise = front).
    normal: Vec3,
    /// Plane offset `⟨normal, v0⟩`.
    d: f32,
    /// Dropped axis of the projection.
    k: u32,
    /// Edges in the projection plane.
    edges: Box<[Edge]>,
    /// Bounding box of every point the kernels can hit: the vertices and the
    /// vertices lifted along the dropped axis onto the plane (they differ when
    /// the vertices are not coplanar).
    bounds: Aabb,
    /// The vertices as given (for exporters and triangulation; the kernels use `edges`).
    vertices: Box<[Vec3]>,
    /// The surface as triangles of non-zero area (cut as [`Polygon::triangles`]
    /// cuts it, with the vertices as given), the pieces the watertight kernels
    /// test; None for an outline ear clipping cannot cut (its edges cross),
    /// which the crossing test serves under either test.
    pieces: Option<Box<[[Vec3; 3]]>>,
    /// Which kernels run: the crossing test, or the watertight pieces.
    test: TriangleTest,
}

impl Polygon {
    /// Build from vertices in order. The first three fix the normal (the NFF
    /// rule), so they must not be collinear; at least three vertices are needed.
    pub fn new(vertices: &[Vec3]) -> Result<Self, GeometryError> {
        let normal = Self::normal_of(vertices)?;
        let abs = normal.abs();
        let k = if abs.x >= abs.y && abs.x >= abs.z {
            0
        } else if abs.y >= abs.z {
            1
        } else {
            2
        };
        let project = |p: Vec3| (p[(k + 1) % 3], p[(k + 2) % 3]);
        let edges = (0..vertices.len())
            .filter_map(|i| {
                let (x0, y0) = project(vertices[i]);
                let (x1, y1) = project(vertices[(i + 1) % vertices.len()]);
                (y0 != y1).then(|| Edge {
                    x0,
                    y0,
                    y1,
                    dx_dy: (x1 - x0) / (y1 - y0),
                })
            })
            .collect();
        let d = normal.dot(vertices[0]);
        // Bound the hit region, not just the vertices: a hit lies on the plane
        // and inside the projected outline, so along the dropped axis it ranges
        // over the plane's heights above the projected vertices. A non-planar
        // polygon (a mangled file) can be hit outside its vertices' box, where
        // a BVH would cull it.
        let lift = |p: Vec3| {
            let mut on_plane = p;
            on_plane[k] = (d - normal.dot(p) + normal[k] * p[k]) / normal[k];
            on_plane
        };
        let lifted = vertices.iter().map(|&v| lift(v)).filter(|p| p.is_finite());
        let mut polygon = Self {
            normal,
            d,
            k: k as u32,
            edges,
            bounds: Aabb::from_points(vertices.iter().copied().chain(lifted)),
            vertices: vertices.into(),
            pieces: None,
            test: TriangleTest::default(),
        };
        // Cut the surface into the watertight kernels' pieces: cut on the
        // plane, with the vertices as given at the corners, so a neighbour
        // with the same vertices shares the pieces' edges bit for bit (a vertex
        // moved onto each polygon's plane rounds differently in each). Pieces
        // of zero area are dropped: no ray hits them, and a BVH cannot hold them.
        polygon.pieces = polygon.ear_clipped().ok().map(|pieces| {
            pieces
                .iter()
                .map(|t| t.map(|i| vertices[i as usize]))
                .filter(|&[a, b, c]| !Triangle::new(a, b, c).is_degenerate())
                .collect()
        });
        Ok(polygon)
    }

    /// Put the polygon under `test`'s kernels (see the module documentation).
    pub fn set_test(&mut self, test: TriangleTest) {
        self.test = test;
    }

    /// The test its kernels run.
    pub fn test(&self) -> TriangleTest {
        self.test
    }

    /// The watertight pieces its kernels test, if it is tested so; a BVH
    /// holds these in its polygon's place, each hit naming the polygon.
    pub fn watertight_pieces(&self) -> Option<&[[Vec3; 3]]> {
        match self.test {
            TriangleTest::Watertight => self.pieces.as_deref(),
            TriangleTest::Barycentric => None,
        }
    }

    /// The unit normal of a polygon with `vertices`, or why they make none:
    /// fewer than three, a non-finite one, or the first three collinear.
    pub fn normal_of(vertices: &[Vec3]) -> Result<Vec3, GeometryError> {
        if vertices.len() < 3 {
            return Err(GeometryError::TooFewVertices(vertices.len()));
        }
        if !vertices.iter().all(|v| v.is_finite()) {
            return Err(GeometryError::NotFinite);
        }
        let n = (vertices[1] - vertices[0]).cross(vertices[2] - vertices[0]);
        n.try_normalize().ok_or(GeometryError::CollinearVertices)
    }

    /// Unit normal.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The vertices in the order given.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// The polygon as triangles on its plane (each vertex moved onto it, so
    /// the triangles cover the surface the crossing test hits), ear-clipped
    /// (Eberly), for engines that take triangles only; none for a polygon of
    /// zero area.
    pub fn triangles(&self) -> Result<Vec<[Vec3; 3]>, EarClipError> {
        let on_plane = self.on_plane();
        Ok(self
            .ear_clipped()?
            .iter()
            .map(|t| t.map(|i| on_plane[i as usize]))
            .collect())
    }

    /// The vertices moved onto the plane.
    fn on_plane(&self) -> Vec<Vec3> {
        let (n, d) = (self.normal, self.d);
        self.vertices.iter().map(|&v| v - (n.dot(v) - d) * n).collect()
    }

    /// The triangles of the outline ear-clipped on the plane, as vertex indices.
    fn ear_clipped(&self) -> Result<Vec<[u32; 3]>, EarClipError> {
        ear_clip(&self.on_plane(), self.normal)
    }

    /// The polygon's plane `⟨normal, p⟩ = d` (fixed by the first three vertices).
    pub fn plane_offset(&self) -> f32 {
        self.d
    }

    /// Number of edges that take part in the crossing test.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }
}

impl Intersect for Polygon {
    /// Scalar kernel.
    #[inline]
    fn intersect(&self, ray: &Ray, prim: u32, hit: &mut Hit) -> bool {
        if let Some(pieces) = self.watertight_pieces() {
            // The ray's shear frame, made once for all the pieces.
            let frame = ShearedRay::new(ray);
            let mut any = false;
            for &[a, b, c] in pieces {
                any |= WatertightTriangle::new(a, b, c).intersect_in(&frame, ray, prim, hit);
            }
            return any;
        }
        let denom = self.normal.dot(ray.dir);
        if !usable_denominator(denom) {
            return false;
        }
        let t = (self.d - self.normal.dot(ray.origin)) / denom;
        if !hit.accepts(t, ray.t_min, prim) {
            return false;
        }
        let k = self.k as usize;
        let (ku, kv) = ((k + 1) % 3, (k + 2) % 3);
        let px = ray.origin[ku] + t * ray.dir[ku];
        let py = ray.origin[kv] + t * ray.dir[kv];
        let mut inside = false;
        for e in self.edges.iter() {
            let straddles = (e.y0 <= py) != (e.y1 <= py);
            if straddles && px < e.x0 + (py - e.y0) * e.dx_dy {
                inside = !inside;
            }
        }
        if !inside {
            return false;
        }
        hit.record(t, prim, 0.0, 0.0);
        true
    }

    /// Packet kernel: every edge (or piece) is tested against all lanes at once.
    #[inline(always)]
    fn intersect_packet<F: SimdFloat>(&self, rays: &RayPacket<F>, prim: u32, hits: &mut HitPacket<F>) {
        if let Some(pieces) = self.watertight_pieces() {
            for &[a, b, c] in pieces {
                WatertightTriangle::new(a, b, c).intersect_packet(rays, prim, hits);
            }
            return;
        }
        let denom = rays.dir.dot_splat(self.normal);
        let t = (F::splat(self.d) - rays.origin.dot_splat(self.normal)) / denom;
        let mask = hits.accepts(rays, t, prim) & usable_denominators(denom);
        if mask.none() {
            return;
        }
        let k = self.k as usize;
        let (ku, kv) = ((k + 1) % 3, (k + 2) % 3);
        let px = rays.origin.axis(ku) + t * rays.dir.axis(ku);
        let py = rays.origin.axis(kv) + t * rays.dir.axis(kv);
        let mut inside = F::splat(0.0);
        for e in self.edges.iter() {
            let straddles = F::splat(e.y0).le(py) ^ F::splat(e.y1).le(py);
            let crosses = px.lt(F::splat(e.x0) + (py - F::splat(e.y0)) * F::splat(e.dx_dy));
            inside = inside ^ (straddles & crosses);
        }
        let zero = F::splat(0.0);
        hits.record(mask & inside, t, prim, zero, zero);
    }
}
