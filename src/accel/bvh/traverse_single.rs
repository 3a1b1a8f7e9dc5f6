//! Single-ray traversal of the binary tree: depth first, nearer child first,
//! culling by the current hit's t. One loop serves nearest-hit and any-hit
//! queries ([`RayQuery`]); packet traversal finishes the lanes it leaves alone
//! with it. Rays traced on their own start in the 4-wide view instead
//! ([`wide::traverse_wide`](super::wide::traverse_wide)), with the same queries.

use std::ops::Range;

use crate::accel::bvh::node::NodeId;
use crate::accel::bvh::ray_box::{FAR_SCALE, SlabRay};
use crate::accel::bvh::wide::traverse_wide;
use crate::accel::bvh::{Bvh, STACK_SIZE};
use crate::accel::stats::Counter;
use crate::geometry::Intersect;
use crate::ray::{Hit, Ray};

/// What a single-ray traversal does in leaves, and how far it looks.
pub trait RayQuery {
    /// The largest t still of interest (the current hit's t for nearest-hit queries).
    fn t_max(&self) -> f32;

    /// Test the leaf primitives `prims`; true ends the traversal.
    fn leaf<S: Counter>(&mut self, bvh: &Bvh, prims: Range<usize>, stats: &mut S) -> bool;
}

/// Traverse the subtree under `start` (whose box the ray is known to meet);
/// returns true if the query ended the traversal early.
#[inline]
pub fn traverse<Q: RayQuery, S: Counter>(
    bvh: &Bvh,
    start: NodeId,
    slab: &SlabRay,
    query: &mut Q,
    stats: &mut S,
) -> bool {
    // Far children still to visit, with their entry t for culling when popped.
    let mut stack = [(0 as NodeId, 0.0f32); STACK_SIZE];
    let mut sp = 0;
    let mut id = start;
    loop {
        let node = bvh.node(id);
        stats.node();
        if node.is_leaf() {
            if query.leaf(bvh, node.prims(), stats) {
                return true;
            }
        } else {
            // Test both children's boxes (one cache line), descend into the nearer.
            let [a, b] = node.children();
            let [box_a, box_b] = &bvh.pair(node.first).0;
            let t_max = query.t_max();
            match (slab.node_entry(box_a, t_max), slab.node_entry(box_b, t_max)) {
                (Some(ta), Some(tb)) => {
                    let (near, far, t_far) = if ta <= tb { (a, b, tb) } else { (b, a, ta) };
                    stack[sp] = (far, t_far);
                    sp += 1;
                    id = near;
                    continue;
                }
                (Some(_), None) => {
                    id = a;
                    continue;
                }
                (None, Some(_)) => {
                    id = b;
                    continue;
                }
                (None, None) => {}
            }
        }
        // Pop the next far child the current hit has not put out of reach
        // (entry t equal to the hit's t stays: the tie rule may still prefer it).
        loop {
            if sp == 0 {
                return false;
            }
            sp -= 1;
            let (next, t_entry) = stack[sp];
            if t_entry <= query.t_max() * FAR_SCALE {
                id = next;
                break;
            }
        }
    }
}

/// The nearest-hit query: every primitive met may improve the record.
pub struct Nearest<'a> {
    /// The ray.
    pub ray: &'a Ray,
    /// Its hit record.
    pub hit: &'a mut Hit,
}

impl RayQuery for Nearest<'_> {
    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.hit.t
    }

    #[inline(always)]
    fn leaf<S: Counter>(&mut self, bvh: &Bvh, prims: Range<usize>, stats: &mut S) -> bool {
        for i in prims {
            stats.prim();
            bvh.prims[i].intersect(self.ray, bvh.prim_ids[i], self.hit);
        }
        false
    }
}

/// The nearest hit of `ray`: unbounded primitives first, then the tree.
#[inline]
pub fn intersect<S: Counter>(bvh: &Bvh, ray: &Ray, stats: &mut S) -> Hit {
    stats.rays(1);
    let mut hit = Hit::none(ray);
    for (p, &id) in bvh.unbounded.iter().zip(&bvh.unbounded_ids) {
        stats.prim();
        p.intersect(ray, id, &mut hit);
    }
    if bvh.prims.is_empty() {
        return hit;
    }
    let slab = SlabRay::new(ray);
    traverse_wide(bvh, &slab, &mut Nearest { ray, hit: &mut hit }, stats);
    hit
}
