//! The round-robin measurement of the traversal bench: every structure built
//! and every ray set traced at every thread count, interleaved round by round.

use std::hint::black_box;
use std::time::Instant;

use crate::bench::timing_hooks::TimingHooks;
use crate::bench::traversal::engines::{Builder, EngineVariant, Structure, engine_variants, pool};
use crate::bench::traversal::measured::{EngineOnScene, Timings};
use crate::bench::traversal::rows::{TraversalRow, row};
use crate::bench::traversal::setup::TraversalSetup;
use crate::engine::{EmbreeIsa, Engine};

/// Timed builds of every structure per thread count, after an untimed round.
const BUILD_ROUNDS: usize = 3;

/// `0..n` in round `round`'s order: forwards in even rounds, backwards in odd
/// ones, so that nothing is measured first (or last) in every round.
fn round_order(round: usize, n: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    if round % 2 == 1 {
        order.reverse();
    }
    order
}

/// Measure `engines` (Embree at each of `embree_isas`) on `setups` at every
/// thread count of `threads`, one rayon pool per count, with no order
/// favouring any of them:
///
/// - builds: three rounds after an untimed one, each building every
///   structure on every thread count (a fresh [`Builder`] per count, since
///   Embree's thread limit is process-wide);
/// - traversal: single rays and packets of every ray set of every scene and
///   engine on every thread count, `rounds` rounds after a warm-up round, all
///   on the structures of the last build.
///
/// Each round goes through thread counts, scenes, engines, kinds and
/// variants, backwards in odd rounds; times pass through
/// the bench timing hooks `hooks`. Rows come per thread count in the order
/// given, then per scene and engine.
pub fn measure(
    setups: &[TraversalSetup],
    engines: &[Engine],
    embree_isas: &[EmbreeIsa],
    threads: &[usize],
    rounds: usize,
    hooks: &TimingHooks,
) -> anyhow::Result<Vec<TraversalRow>> {
    let mut thread_counts: Vec<usize> = Vec::new();
    for t in threads.iter().map(|&t| t.max(1)) {
        if !thread_counts.contains(&t) {
            thread_counts.push(t);
        }
    }
    anyhow::ensure!(!thread_counts.is_empty(), "no thread count to measure");
    let variants = engine_variants(engines, embree_isas)?;
    let pools = thread_counts
        .iter()
        .map(|&t| pool(t, &variants))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let keys: Vec<(&TraversalSetup, EngineVariant)> = setups
        .iter()
        .flat_map(|setup| variants.iter().map(move |&v| (setup, v)))
        .collect();
    let empty = |setup: &TraversalSetup| Timings {
        build_ms: Vec::new(),
        per_ray: vec![Default::default(); setup.sets.len()],
    };
    // timings[t][c]: thread count t, case c.
    let mut timings: Vec<Vec<Timings>> = thread_counts
        .iter()
        .map(|_| keys.iter().map(|(setup, _)| empty(setup)).collect())
        .collect();

    // Build every structure on every thread count, round by round; the
    // structures of the very last builds are kept for tracing, every other
    // one is dropped before the next builder exists (it holds its device).
    let mut structures: Vec<Option<Structure>> = keys.iter().map(|_| None).collect();
    for round in 0..=BUILD_ROUNDS {
        let order = round_order(round, thread_counts.len());
        for (step, &t) in order.iter().enumerate() {
            let keep = round == BUILD_ROUNDS && step + 1 == order.len();
            let builder = Builder::new(engines, embree_isas, thread_counts[t])?;
            pools[t].install(|| -> anyhow::Result<()> {
                for c in round_order(round, keys.len()) {
                    let (setup, variant) = keys[c];
                    let start = Instant::now();
                    let structure = builder.build(variant, &setup.prims)?;
                    let ms = 1e3 * start.elapsed().as_secs_f64();
                    if round > 0 {
                        timings[t][c].build_ms.push(ms);
                    }
                    if keep {
                        structures[c] = Some(structure);
                    }
                }
                Ok(())
            })?;
        }
    }
    let mut cases = keys
        .iter()
        .zip(structures)
        .map(|(&(setup, variant), structure)| {
            Ok(EngineOnScene {
                setup,
                variant,
                structure: structure.ok_or_else(|| anyhow::anyhow!("{} was not built", variant.name()))?,
                hits: vec![0; setup.sets.len()],
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;

    // Trace; round 0 warms every pool and structure up (caches, page faults)
    // and is not kept.
    let steps: Vec<(usize, usize)> = (0..thread_counts.len())
        .flat_map(|t| (0..cases.len()).map(move |c| (t, c)))
        .collect();
    for round in 0..=rounds {
        for step in round_order(round, steps.len()) {
            let (t, c) = steps[step];
            let case = &mut cases[c];
            let timing = &mut timings[t][c];
            pools[t].install(|| {
                for (k, set) in case.setup.sets.iter().enumerate() {
                    for (v, variant) in ["single", "packet8"].into_iter().enumerate() {
                        let start = Instant::now();
                        let hits = black_box(case.structure.trace(set, v == 1));
                        let rays = set.rays.len() as f64;
                        let seconds = hooks.apply(variant, rays, start.elapsed().as_secs_f64());
                        if round == 0 && v == 0 {
                            case.hits[k] = hits;
                        }
                        if round > 0 {
                            timing.per_ray[k][v].push(seconds / set.rays.len().max(1) as f64);
                        }
                    }
                }
            });
        }
    }

    let mut rows = Vec::with_capacity(timings.len() * cases.len());
    for (t, of_threads) in timings.iter().enumerate() {
        for (case, timing) in cases.iter().zip(of_threads) {
            // The first case of the engine: the case itself at the latest.
            let first = cases.iter().position(|c| c.variant == case.variant).unwrap_or(0);
            // Embree on the same rays: its first ISA setting measured.
            let embree = cases.iter().position(|c| {
                case.variant.engine == Engine::Raypack
                    && c.variant.engine == Engine::Embree
                    && std::ptr::eq(c.setup, case.setup)
            });
            rows.push(row(
                case,
                timing,
                &of_threads[first].per_ray,
                embree.map(|e| &of_threads[e].per_ray[..]),
                thread_counts[t],
                rounds,
            )?);
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::rays::RayKind;

    #[test]
    fn odd_rounds_go_backwards() {
        assert_eq!(round_order(0, 3), [0, 1, 2]);
        assert_eq!(round_order(1, 3), [2, 1, 0]);
        assert_eq!(round_order(2, 3), [0, 1, 2]);
        assert!(round_order(1, 0).is_empty());
    }

    #[test]
    fn every_thread_count_gets_a_row_per_scene_with_every_round_kept() {
        let kinds = [RayKind::Primary, RayKind::Ao];
        let setups = [
            TraversalSetup::generated("mesh", 100, (16, 16), 32, &kinds).expect("known kind"),
            TraversalSetup::generated("mesh", 300, (16, 16), 32, &kinds).expect("known kind"),
        ];
        let hooks = TimingHooks::default();
        let rows = measure(&setups, &[Engine::Raypack], &[], &[2, 1, 2], 3, &hooks).unwrap();
        // A thread count given twice is measured once, in the order given.
        let layout: Vec<_> = rows.iter().map(|r| (r.threads, r.primitives)).collect();
        let [small, large] = setups.each_ref().map(|s| s.prims.len());
        assert!(small < large);
        assert_eq!(layout, [(2, small), (2, large), (1, small), (1, large)]);
        for row in &rows {
            assert_eq!(row.build_ms.samples, BUILD_ROUNDS, "{}", row.scene);
            for k in &row.kinds {
                assert_eq!(k.single_mrays.samples, 3);
                assert_eq!(k.packet_mrays.samples, 3);
            }
        }
        // The same structures and rays at either thread count: the same hits.
        for (two, one) in rows[..2].iter().zip(&rows[2..]) {
            let hits = |r: &TraversalRow| r.kinds.iter().map(|k| k.hits).collect::<Vec<_>>();
            assert_eq!(hits(two), hits(one));
            assert!(hits(one)[0] > 0, "the camera sees the mesh");
        }
        assert!(measure(&setups, &[Engine::Raypack], &[], &[], 1, &hooks).is_err());
    }
}
