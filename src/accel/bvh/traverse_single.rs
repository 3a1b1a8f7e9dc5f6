//! Single-ray traversal of the wide tree: depth first, children met pushed in
//! order of entry t so the nearest is visited next, culling by the current hit's
//! t. A child pushed is prefetched ([`Bvh::prefetch`]), so its lines are on their
//! way while the ray works through the nearer ones (incoherent rays wait on
//! memory more than on arithmetic). One loop serves nearest-hit and any-hit queries ([`RayQuery`]); packet
//! traversal finishes the lanes it leaves alone with it.
//!
//! Several rays can walk at once, one visit of each in turn
//! ([`traverse_interleaved`]): a ray's next visit waits on the node it goes
//! to, and the other rays' visits fill that wait. Packets of rays from all
//! over a scene are traced so (see `RayPacket::is_scattered`).

use std::mem::MaybeUninit;

use crate::accel::bvh::leaf::LeafRef;
use crate::accel::bvh::query::{INTERLEAVED, RayQuery};
use crate::accel::bvh::ray_box::{FAR_SCALE, SlabRay};
use crate::accel::bvh::stack::{StackSlots, WIDE_STACK_SLOTS};
use crate::accel::bvh::tree::Bvh;
use crate::accel::bvh::tree::TreeWidth;
use crate::accel::bvh::wide::{ChildRef, RayTreeLanes};
use crate::accel::stats::Counter;
use crate::geometry::{LazyBlockRay, LeafRay};
use crate::ray::{Hit, Ray};
use crate::simd::Simd8;

/// Traverse the subtree under `start` of the wide tree of width `W` (whose
/// box the ray is known to meet, or [`ChildRef::ROOT`]); returns true if the
/// query ended the traversal early.
#[inline(always)]
pub fn traverse<N: Simd8, W: TreeWidth, Q: RayQuery, S: Counter>(
    bvh: &Bvh,
    start: ChildRef,
    slab: &SlabRay,
    query: &mut Q,
    stats: &mut S,
) -> bool {
    // The cursor is a local apart from the slots, so it stays in registers.
    let (mut stack, mut cursor) = (StackSlots::new(), Cursor::new(start));
    loop {
        if let Some(ended_early) = cursor.step::<N, W, Q, S, false>(&mut stack, bvh, slab, query, stats) {
            return ended_early;
        }
    }
}

/// Traverse the subtree under `start` with each ray of `walks` (its packet
/// lane, for [`Counter::lane`], its slab ray and its query; at most
/// [`INTERLEAVED`]), one node visit of each in turn; returns the mask of the
/// rays whose query ended early. An incoherent ray waits on memory at nearly
/// every visit, and its next visit needs the node it is waiting for; so each
/// walk prefetches the child it goes to next, and the other rays' visits fill
/// the wait (the misses of several rays overlap, where one ray's come one
/// after the other).
#[inline(always)]
pub fn traverse_interleaved<N: Simd8, W: TreeWidth, Q: RayQuery, S: Counter>(
    bvh: &Bvh,
    start: ChildRef,
    walks: &mut [(usize, SlabRay, Q)],
    stats: &mut S,
) -> u32 {
    let count = walks.len().min(INTERLEAVED);
    // The walks' stacks are left uninitialised (3 KiB each), as one walk's are.
    let mut states = [const { MaybeUninit::<Walk>::uninit() }; INTERLEAVED];
    for state in &mut states[..count] {
        state.write(Walk::new(start));
    }
    let (mut walking, mut ended_early) = ((1u32 << count) - 1, 0);
    while walking != 0 {
        let mut bits = walking;
        while bits != 0 {
            let k = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let (lane, slab, query) = &mut walks[k];
            stats.lane(*lane);
            // SAFETY: the first `count` states were written above.
            let Walk { stack, cursor } = unsafe { states[k].assume_init_mut() };
            if let Some(early) = cursor.step::<N, W, Q, S, true>(stack, bvh, slab, query, stats) {
                walking &= !(1 << k);
                ended_early |= u32::from(early) << k;
            }
        }
    }
    ended_early
}

/// The children met but not yet visited of one ray's walk, with their entry t. 3 KiB.
type WalkStack = StackSlots<(ChildRef, f32), WIDE_STACK_SLOTS>;

/// One ray's walk through the wide tree, as interleaved walks keep it: its
/// stack and its cursor.
struct Walk {
    stack: WalkStack,
    cursor: Cursor,
}

impl Walk {
    /// A walk that starts at `start`.
    #[inline(always)]
    fn new(start: ChildRef) -> Self {
        Self {
            stack: StackSlots::new(),
            cursor: Cursor::new(start),
        }
    }
}

/// Where one ray's walk stands: the child it visits next, and how many
/// children wait on its stack. 16 bytes.
#[derive(Clone, Copy)]
struct Cursor {
    next: ChildRef,
    pending: usize,
}

impl Cursor {
    /// A walk that starts at `start`, with nothing pending.
    #[inline(always)]
    fn new(start: ChildRef) -> Self {
        Self {
            next: start,
            pending: 0,
        }
    }

    /// Visit the next child: Some(true) if the query ended the traversal,
    /// Some(false) if no child is left, None to go on. With `PREFETCH_NEXT`
    /// (walks interleaved with others) the child chosen next is prefetched
    /// too; a walk alone loads it at once.
    #[inline(always)]
    fn step<N: Simd8, W: TreeWidth, Q: RayQuery, S: Counter, const PREFETCH_NEXT: bool>(
        &mut self,
        stack: &mut WalkStack,
        bvh: &Bvh,
        slab: &SlabRay,
        query: &mut Q,
        stats: &mut S,
    ) -> Option<bool> {
        let next = self.next;
        stats.node();
        if next.is_leaf() {
            if !next.is_empty() && query.leaf::<N, S>(bvh, next.contents(), stats) {
                return Some(true);
            }
        } else {
            // Test all children's boxes at once.
            let node = &W::nodes(bvh)[next.node()];
            let (mut bits, t) = node.entry::<N>(slab, query.t_max());
            let t = t.as_ref();
            let rest = bits & bits.wrapping_sub(1);
            if bits != 0 && rest & rest.wrapping_sub(1) == 0 {
                // One or two children met (nine visits in ten): descend into
                // the nearer and push the other, if any. Which is nearer, and
                // whether there is a second, are coin tosses a branch
                // predictor loses, so both are settled by selects.
                let i = bits.trailing_zeros() as usize;
                let j = rest.trailing_zeros() as usize % W::LANES; // any slot when `rest` is 0
                let j_nearer = Q::NEAREST_FIRST && rest != 0 && t[j] < t[i];
                let (near, far) = std::hint::select_unpredictable(j_nearer, (j, i), (i, j));
                // The far child is wanted later: have its lines loaded by then.
                if rest != 0 {
                    bvh.prefetch::<W>(node.slot(far));
                }
                self.pending = stack.push_if(self.pending, (node.slot(far), t[far]), rest != 0);
                self.next = node.slot(near);
                if PREFETCH_NEXT {
                    bvh.prefetch::<W>(self.next);
                }
                return None;
            }
            // More: push them all, a nearest-hit query's in order of
            // decreasing entry t, so the nearest is popped next. Each child
            // goes straight to its place in the run, its rank among the
            // children met (`ChildRanks`): an insertion sort's swaps are coin
            // tosses on incoherent rays, and a mispredicted branch costs more
            // than the compares.
            let (base, met) = (self.pending, bits);
            let ranks = ChildRanks::<N>::new(t);
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                bvh.prefetch::<W>(node.slot(i));
                if Q::NEAREST_FIRST {
                    stack.put(base + ranks.rank(met, i, t[i]), (node.slot(i), t[i]));
                } else {
                    self.pending = stack.push_if(self.pending, (node.slot(i), t[i]), true);
                }
            }
            if Q::NEAREST_FIRST {
                self.pending = base + met.count_ones() as usize;
            }
        }
        // Pop the next child the current hit has not put out of reach (entry t
        // equal to the hit's t stays: the tie rule may still prefer it). It
        // was prefetched when pushed. An any-hit query's reach never shrinks,
        // so what it pushed stays in reach.
        loop {
            let Some(((child, t_entry), pending)) = stack.pop(self.pending) else {
                return Some(false);
            };
            self.pending = pending;
            if !Q::NEAREST_FIRST || t_entry <= query.t_max() * FAR_SCALE {
                self.next = child;
                return None;
            }
        }
    }
}

/// The entry t of a wide node's children, in the instruction set's 8-lane
/// vectors (one or two), for ranking the children met by t. 72 bytes.
struct ChildRanks<N: Simd8> {
    halves: [N; 2],
    lanes: usize,
}

impl<N: Simd8> ChildRanks<N> {
    /// The children's entry t (8 or 16 of them).
    #[inline(always)]
    fn new(t: &[f32]) -> Self {
        let half = |h: usize| {
            let mut lanes = [0.0; 8];
            if let Some(t) = t.get(8 * h..8 * h + 8) {
                lanes.copy_from_slice(t);
            }
            N::from_array(lanes)
        };
        Self {
            halves: [half(0), half(1)],
            lanes: t.len(),
        }
    }

    /// Child `i`'s place (its entry t is `t_i`), counted from the bottom, in
    /// the run of the children `met` stacked by decreasing entry t: how many
    /// of them enter later than it, or at the same t from a lower slot (the
    /// order a stable sort of the children in slot order gives). Every child
    /// met gets its own place, its t not being NaN (a NaN entry fails the box
    /// test).
    #[inline(always)]
    fn rank(&self, met: u32, i: usize, t_i: f32) -> usize {
        let t_i = N::splat(t_i);
        let mut before = 0;
        for (h, half) in self.halves.iter().enumerate().take(self.lanes / 8) {
            let later = half.gt(t_i).bitmask() << (8 * h);
            let tied = half.eq(t_i).bitmask() << (8 * h);
            before |= later | (tied & ((1 << i) - 1));
        }
        (before & met).count_ones() as usize
    }
}

/// The nearest-hit query: every primitive met may improve the record. `R`
/// says when the ray is prepared for the leaves' kernels: at the first leaf
/// (a walk from the root), or at once.
pub struct Nearest<'a, R = LazyBlockRay<'a>> {
    /// The ray, held for the leaves' kernels.
    ray: R,
    /// Its hit record.
    hit: &'a mut Hit,
}

impl<'a, R: LeafRay<'a>> Nearest<'a, R> {
    /// The nearest-hit query of `ray`, improving on `hit`.
    #[inline(always)]
    pub fn new(ray: &'a Ray, hit: &'a mut Hit) -> Self {
        Self {
            ray: R::hold(ray),
            hit,
        }
    }
}

impl<'a, R: LeafRay<'a>> RayQuery for Nearest<'a, R> {
    #[inline(always)]
    fn t_max(&self) -> f32 {
        self.hit.t
    }

    #[inline(always)]
    fn leaf<N: Simd8, S: Counter>(&mut self, bvh: &Bvh, leaf: LeafRef, stats: &mut S) -> bool {
        bvh.leaves()
            .intersect::<N, S>(leaf, self.ray.get(), self.hit, false, stats);
        false
    }
}

/// Run `query` for `ray` over the whole BVH: the leaf of unbounded
/// primitives first, then the tree; returns true if the query ended early.
/// `N` is the instruction set's 8-lane type.
#[inline(always)]
pub fn trace<N: Simd8, Q: RayQuery, S: Counter>(bvh: &Bvh, ray: &Ray, query: &mut Q, stats: &mut S) -> bool {
    stats.rays(1);
    if let Some(leaf) = bvh.unbounded_leaf()
        && query.leaf::<N, S>(bvh, leaf, stats)
    {
        return true;
    }
    !bvh.is_empty()
        && traverse::<N, RayTreeLanes, Q, S>(bvh, ChildRef::ROOT, &SlabRay::new(ray), query, stats)
}

/// The nearest hit of `ray` written into `hit` (whatever it held before), with
/// the instruction set's 8-lane type `N`. Callers with an array of records
/// trace into it in place: a record returned by value and then copied goes
/// through the stack, and the copy's wide loads stall on the narrower stores
/// just made.
#[inline(always)]
pub fn intersect_into<N: Simd8, S: Counter>(bvh: &Bvh, ray: &Ray, hit: &mut Hit, stats: &mut S) {
    *hit = Hit::none(ray);
    trace::<N, _, S>(bvh, ray, &mut Nearest::<LazyBlockRay>::new(ray, hit), stats);
}

/// The nearest hit of `ray`, with the instruction set's 8-lane type `N`.
#[inline(always)]
pub fn intersect<N: Simd8, S: Counter>(bvh: &Bvh, ray: &Ray, stats: &mut S) -> Hit {
    let mut hit = Hit::none(ray);
    intersect_into::<N, S>(bvh, ray, &mut hit, stats);
    hit
}

#[cfg(test)]
mod tests {
    use wide::f32x8;

    use super::*;
    use crate::rng::Rng;

    /// Ranks put the children met in the order a stable sort by decreasing
    /// entry t gives, ties (which random t drawn from few values make common)
    /// by slot, for 8- and 16-wide nodes.
    #[test]
    fn ranks_order_the_children_met_by_decreasing_entry_t() {
        let mut rng = Rng::new(54);
        for lanes in [8, 16] {
            for _ in 0..2_000 {
                let t: Vec<f32> = (0..lanes).map(|_| rng.below(5) as f32 * 0.25).collect();
                let met = rng.next_u32() & (u32::MAX >> (32 - lanes));
                let mut expected: Vec<usize> = (0..lanes).filter(|&i| met >> i & 1 == 1).collect();
                expected.sort_by(|&a, &b| t[b].total_cmp(&t[a]));
                let ranks = ChildRanks::<f32x8>::new(&t);
                let mut placed = vec![None; expected.len()];
                for &i in &expected {
                    let place = ranks.rank(met, i, t[i]);
                    assert!(
                        placed[place].is_none(),
                        "two children at {place}: {t:?}, met {met:b}"
                    );
                    placed[place] = Some(i);
                }
                let placed: Vec<usize> = placed.into_iter().flatten().collect();
                assert_eq!(placed, expected, "t {t:?}, met {met:b}");
            }
        }
    }
}
