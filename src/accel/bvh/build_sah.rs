//! The binned SAH builder (I. Wald, "On fast construction of SAH-based bounding
//! volume hierarchies", IEEE Symposium on Interactive Ray Tracing, 2007).
//!
//! Top-down: at each node the primitives' centroids are dropped into `bins`
//! equal bins per axis; sweeping the bins from both sides gives the surface area
//! heuristic (MacDonald & Booth, 1990) of every bin boundary,
//!
//! ```text
//! cost(split) = C_trav + C_isect · (n_L·A_L + n_R·A_R) / A
//! cost(leaf)  = C_isect · n
//! ```
//!
//! and the node becomes a leaf when that is cheaper than the best split and small
//! enough; otherwise its primitives are partitioned at the best boundary and both
//! halves are built, on two rayon tasks when the node is large. Where binning
//! cannot separate the primitives (all centroids in one point) or the tree grows
//! too deep, the node is split at the median centroid instead, which bounds the
//! depth by [`SAH_DEPTH_LIMIT`] + 32.

use glam::Vec3;

use crate::accel::bvh::node::{Node, NodePair};
use crate::bounds::Aabb;

/// How a BVH is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildOptions {
    /// SAH bins per axis, clamped to `[2, 32]` (8–32 is the useful range).
    pub bins: usize,
    /// Largest leaf the SAH may choose; larger nodes are always split.
    pub max_leaf_size: usize,
    /// SAH cost of visiting a node, relative to…
    pub traversal_cost: f32,
    /// …the cost of one ray-primitive test.
    pub intersection_cost: f32,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            bins: 16,
            max_leaf_size: 8,
            traversal_cost: 1.0,
            intersection_cost: 1.0,
        }
    }
}

/// Most bins per axis.
const MAX_BINS: usize = 32;

/// Depth from which nodes are split at the median instead of by the SAH.
pub const SAH_DEPTH_LIMIT: usize = 60;

/// Nodes with at least this many primitives build their two children in parallel.
const PARALLEL_MIN: usize = 4096;

/// The built hierarchy: node pairs (root in pair 0, side 0) and the primitive
/// order of the leaves (indices into the input boxes).
pub struct Built {
    /// The nodes.
    pub pairs: Vec<NodePair>,
    /// Leaf primitive `i` is input primitive `order[i]`.
    pub order: Vec<u32>,
}

/// Build over the primitive boxes `boxes` (finite, non-empty list).
pub fn build(boxes: &[Aabb], options: &BuildOptions) -> Built {
    let centroids: Vec<Vec3> = boxes.iter().map(|b| 0.5 * b.min + 0.5 * b.max).collect();
    let ctx = Context {
        boxes,
        centroids: &centroids,
        bins: options.bins.clamp(2, MAX_BINS),
        max_leaf: options.max_leaf_size.max(1),
        c_trav: options.traversal_cost,
        c_isect: options.intersection_cost,
    };
    let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
    let bounds = boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
    let tree = ctx.subtree(&mut order, 0, bounds, 0);
    // Flatten depth first: a node's children pair, then the left subtree, then the right.
    let mut pairs = vec![NodePair([Node::EMPTY; 2])];
    pairs[0].0[0] = emit(&tree, &mut pairs);
    Built { pairs, order }
}

/// The tree while it is being built.
enum Temp {
    Leaf {
        bounds: Aabb,
        first: u32,
        count: u32,
    },
    Inner {
        bounds: Aabb,
        axis: u32,
        children: Box<[Temp; 2]>,
    },
}

/// Write `t`'s subtree into `pairs`, returning the node for `t` itself.
fn emit(t: &Temp, pairs: &mut Vec<NodePair>) -> Node {
    match t {
        Temp::Leaf { bounds, first, count } => Node::leaf(*bounds, *first, *count),
        Temp::Inner {
            bounds,
            axis,
            children,
        } => {
            let pair = pairs.len();
            pairs.push(NodePair([Node::EMPTY; 2]));
            let left = emit(&children[0], pairs);
            let right = emit(&children[1], pairs);
            pairs[pair] = NodePair([left, right]);
            Node::inner(*bounds, pair as u32, *axis)
        }
    }
}

/// The best split found by binning.
struct Split {
    axis: usize,
    /// Bins `0..=last_left` go left.
    last_left: usize,
    cost: f32,
    left: Aabb,
    right: Aabb,
}

/// One SAH bin: the primitives whose centroids fall in it. 28 bytes.
#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: u32,
}

/// Everything a node's build reads.
struct Context<'a> {
    boxes: &'a [Aabb],
    centroids: &'a [Vec3],
    bins: usize,
    max_leaf: usize,
    c_trav: f32,
    c_isect: f32,
}

impl Context<'_> {
    /// Build the node holding `refs` (primitives `first..first + refs.len()` of
    /// the final order) whose box is `bounds`.
    fn subtree(&self, refs: &mut [u32], first: u32, bounds: Aabb, depth: usize) -> Temp {
        let n = refs.len();
        let leaf = Temp::Leaf {
            bounds,
            first,
            count: n as u32,
        };
        if n <= 1 {
            return leaf;
        }
        let centroid_bounds = Aabb::from_points(refs.iter().map(|&r| self.centroids[r as usize]));
        let split = if depth < SAH_DEPTH_LIMIT {
            self.best_split(refs, &bounds, &centroid_bounds)
        } else {
            None
        };
        let leaf_cost = self.c_isect * n as f32;
        let (axis, mid, left, right) = match split {
            Some(s) if n > self.max_leaf || s.cost < leaf_cost => {
                let scale = self.bin_scale(&centroid_bounds, s.axis);
                let min = centroid_bounds.min[s.axis];
                let mid = partition(refs, |r| {
                    self.bin_of(self.centroids[r as usize][s.axis], min, scale) <= s.last_left
                });
                (s.axis, mid, s.left, s.right)
            }
            _ if n <= self.max_leaf => return leaf,
            _ => self.median_split(refs, &centroid_bounds),
        };
        let (l, r) = refs.split_at_mut(mid);
        let mut build_left = || self.subtree(l, first, left, depth + 1);
        let mut build_right = || self.subtree(r, first + mid as u32, right, depth + 1);
        let children = if n >= PARALLEL_MIN {
            let (a, b) = rayon::join(build_left, build_right);
            [a, b]
        } else {
            [build_left(), build_right()]
        };
        Temp::Inner {
            bounds,
            axis: axis as u32,
            children: Box::new(children),
        }
    }

    /// Bins per unit of centroid extent along `axis` (0 when the axis cannot be binned).
    fn bin_scale(&self, centroid_bounds: &Aabb, axis: usize) -> f32 {
        let extent = centroid_bounds.max[axis] - centroid_bounds.min[axis];
        let scale = self.bins as f32 / extent;
        if extent > 0.0 && scale.is_finite() {
            scale
        } else {
            0.0
        }
    }

    /// The bin of a centroid coordinate `c`.
    #[inline(always)]
    fn bin_of(&self, c: f32, min: f32, scale: f32) -> usize {
        // `as usize` saturates (and maps NaN to 0); the top boundary falls in the last bin.
        (((c - min) * scale) as usize).min(self.bins - 1)
    }

    /// The cheapest SAH split over all axes and bin boundaries, if any separates the primitives.
    fn best_split(&self, refs: &[u32], bounds: &Aabb, centroid_bounds: &Aabb) -> Option<Split> {
        let scales = [0, 1, 2].map(|axis| self.bin_scale(centroid_bounds, axis));
        if scales == [0.0; 3] {
            return None;
        }
        // Fill the bins of all three axes in one pass over the primitives.
        let empty = Bin {
            bounds: Aabb::EMPTY,
            count: 0,
        };
        let mut bins = [[empty; MAX_BINS]; 3];
        for &r in refs {
            let (c, b) = (self.centroids[r as usize], self.boxes[r as usize]);
            for axis in 0..3 {
                let bin = &mut bins[axis][self.bin_of(c[axis], centroid_bounds.min[axis], scales[axis])];
                bin.bounds = bin.bounds.union(b);
                bin.count += 1;
            }
        }
        let inv_area = 1.0 / bounds.surface_area();
        let mut best: Option<Split> = None;
        for (axis, bins) in bins.iter().enumerate() {
            if scales[axis] == 0.0 {
                continue;
            }
            let bins = &bins[..self.bins];
            // Right-to-left sweep: the box and count of bins `i..`.
            let mut right = [empty; MAX_BINS];
            let mut acc = empty;
            for i in (1..bins.len()).rev() {
                acc = Bin {
                    bounds: acc.bounds.union(bins[i].bounds),
                    count: acc.count + bins[i].count,
                };
                right[i] = acc;
            }
            // Left-to-right sweep, pricing the boundary after bin `i`.
            let mut left = empty;
            for i in 0..bins.len() - 1 {
                left = Bin {
                    bounds: left.bounds.union(bins[i].bounds),
                    count: left.count + bins[i].count,
                };
                let r = right[i + 1];
                if left.count == 0 || r.count == 0 {
                    continue;
                }
                let weighted =
                    left.count as f32 * left.bounds.surface_area() + r.count as f32 * r.bounds.surface_area();
                let cost = self.c_trav + self.c_isect * weighted * inv_area;
                // `<` is false for NaN costs (infinite areas): such splits are never chosen.
                if best.as_ref().is_none_or(|b| cost < b.cost) {
                    best = Some(Split {
                        axis,
                        last_left: i,
                        cost,
                        left: left.bounds,
                        right: r.bounds,
                    });
                }
            }
        }
        best.filter(|b| b.cost.is_finite())
    }

    /// Split at the median centroid of the widest centroid axis; returns
    /// `(axis, left count, left box, right box)`.
    fn median_split(&self, refs: &mut [u32], centroid_bounds: &Aabb) -> (usize, usize, Aabb, Aabb) {
        let e = centroid_bounds.extent();
        let axis = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        let mid = refs.len() / 2;
        refs.select_nth_unstable_by(mid, |&a, &b| {
            self.centroids[a as usize][axis].total_cmp(&self.centroids[b as usize][axis])
        });
        let union = |rs: &[u32]| {
            rs.iter()
                .fold(Aabb::EMPTY, |acc, &r| acc.union(self.boxes[r as usize]))
        };
        (axis, mid, union(&refs[..mid]), union(&refs[mid..]))
    }
}

/// Reorder `refs` so the elements where `goes_left` holds come first; returns their count.
fn partition(refs: &mut [u32], goes_left: impl Fn(u32) -> bool) -> usize {
    let (mut i, mut j) = (0, refs.len());
    while i < j {
        if goes_left(refs[i]) {
            i += 1;
        } else {
            j -= 1;
            refs.swap(i, j);
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partition_splits_by_predicate() {
        let mut v: Vec<u32> = (0..100).collect();
        let k = partition(&mut v, |x| x % 3 == 0);
        assert_eq!(k, 34);
        assert!(v[..k].iter().all(|x| x % 3 == 0));
        assert!(v[k..].iter().all(|x| x % 3 != 0));
        let mut sorted = v.clone();
        sorted.sort();
        assert_eq!(sorted, (0..100).collect::<Vec<_>>());
    }
}
