//! Queries built on nearest hits, for any [`Accel`]: every surface crossing
//! along a ray ([`all_hits`]) and whether a point lies inside closed meshes
//! ([`is_inside`], the parity of crossings). They are as right as the
//! triangle test under them: with the watertight test no ray slips between
//! two triangles, so the count is exact up to the merging of the hits at a
//! shared edge or vertex, which this module does.
//!
//! A ray through an edge or a vertex hits every triangle there, at the same
//! t up to rounding. Those hits are one crossing when the triangles face the
//! same way along the ray (the ray passes from one side to the other), and
//! two when they face opposite ways (it touches a ridge or a valley and goes
//! back out). So consecutive hits met from the same side merge when their
//! triangles share an edge, however far apart rounding put their t (two
//! consistently wound triangles sharing an edge split space in two, so a
//! line crossing both at distinct points alternates sides; a ray nearly along
//! the surface gets t far apart from the two planes), or share a vertex and
//! their t agree within [`SAME_CROSSING`].

use glam::Vec3;

use crate::accel::Accel;
use crate::geometry::Primitive;
use crate::ray::{Hit, Ray};

/// Relative difference of t below which hits on triangles sharing a vertex
/// are one crossing: far above the rounding of two kernels' t at a shared
/// edge (a few ulps), far below any distance between two crossings of a
/// mesh whose features are not 10⁵ times smaller than their distance from
/// the ray's origin.
pub const SAME_CROSSING: f32 = 1e-5;

/// Every crossing of `ray` with the primitives `accel` was built over (in
/// `prims` order), nearest first: each primitive at most once, and the hits
/// at a shared edge or vertex merged into one where the ray crosses there
/// (see the module documentation). Found by nearest-hit queries, each
/// starting just past the last hit.
pub fn all_hits<A: Accel>(accel: &A, prims: &[Primitive], ray: &Ray) -> Vec<Hit> {
    let mut hits: Vec<Hit> = Vec::new();
    let mut rest = *ray;
    loop {
        let hit = accel.intersect(&rest);
        if !hit.is_hit() {
            return hits;
        }
        // t only grows and every primitive meets the ray at one t, so this ends.
        rest.t_min = hit.t.next_up();
        match hits.last() {
            Some(last) if same_crossing(prims, ray, last, &hit) => {}
            _ => hits.push(hit),
        }
    }
}

/// True when `a` and `b` are one crossing of `ray`: hits met from the same
/// side on triangles that share an edge, or a vertex with t within [`SAME_CROSSING`].
fn same_crossing(prims: &[Primitive], ray: &Ray, a: &Hit, b: &Hit) -> bool {
    let (Primitive::Triangle(ta), Primitive::Triangle(tb)) =
        (&prims[a.prim as usize], &prims[b.prim as usize])
    else {
        return false;
    };
    let (va, vb) = (ta.vertices(), tb.vertices());
    let shared = va.iter().filter(|p| vb.contains(p)).count();
    let close = (a.t - b.t).abs() <= SAME_CROSSING * a.t.abs().max(b.t.abs());
    let side = |n: Vec3| n.dot(ray.dir) > 0.0;
    side(ta.normal()) == side(tb.normal()) && (shared >= 2 || (shared == 1 && close))
}

/// Directions of the parity rays (unit length): far from every axis and diagonal, so that
/// they do not run along the grid lines of axis-aligned meshes.
const PARITY_DIRECTIONS: [Vec3; 3] = [
    Vec3::new(0.539_146_9, 0.617_193, 0.573_056_1),
    Vec3::new(-0.711_25, 0.127_313_8, 0.691_313_7),
    Vec3::new(0.291_035_5, -0.893_735_6, 0.341_372_3),
];

/// True when `point` lies inside the closed meshes among the primitives
/// `accel` was built over: an odd number of crossings ([`all_hits`]) along
/// each of three rays from it, by majority (a ray that happens to touch the
/// surface tangentially at a vertex is outvoted). A point on the surface may
/// go either way.
pub fn is_inside<A: Accel>(accel: &A, prims: &[Primitive], point: Vec3) -> bool {
    let odd = PARITY_DIRECTIONS
        .iter()
        .filter(|&&dir| all_hits(accel, prims, &Ray::unbounded(point, dir)).len() % 2 == 1)
        .count();
    odd >= 2
}
