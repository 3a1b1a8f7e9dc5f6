//! The round-robin measurement of the traversal bench: every structure built
//! and every ray set traced at every thread count, interleaved round by round.

use std::hint::black_box;
use std::time::{Duration, Instant};

use crate::bench::rays::Query;
use crate::bench::timing_hooks::TimingHooks;
use crate::bench::traversal::engines::{Builder, EngineVariant, TraceKind, engine_variants, pool};
use crate::bench::traversal::measured::{EngineOnScene, Timings};
use crate::bench::traversal::rows::{TraversalRow, rows};
use crate::bench::traversal::setup::TraversalSetup;
use crate::bench::traversal::trace::{PATHS, path_name};
use crate::embree_settings::EmbreeIsa;
use crate::engines::{Built, Engine};
use crate::render::settings::KernelKind;

/// Timed builds of every structure per thread count, after an untimed round.
const BUILD_ROUNDS: usize = 3;

/// The least build time one round's sample of a structure sums: a structure
/// that builds faster is built again (each build dropped, untimed, before the
/// next), and the sample is the mean of its builds. A small scene's build of
/// a millisecond or less moved 10-30% from one build to the next, so three
/// single builds left its cell to chance; the dragon's (hundreds of ms) is
/// still one build a round.
const BUILD_SAMPLE: Duration = Duration::from_millis(30);

/// How builds are timed, for the benches' footnotes.
pub fn builds_how() -> String {
    format!(
        "builds: {BUILD_ROUNDS} rounds after a warm-up, each a structure's mean build time over builds summing {} ms (one build where that takes longer)",
        BUILD_SAMPLE.as_millis()
    )
}

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
///   Embree's thread limit is process-wide), then an untimed build at the
///   most threads, whose structures are traced;
/// - traversal: single rays, 8- and 16-ray packets of every ray set of every
///   scene and engine on every thread count, `rounds` rounds after a warm-up round, all
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
    let thread_counts = distinct_thread_counts(threads)?;
    let variants = engine_variants(engines, embree_isas)?;
    let pools = thread_counts
        .iter()
        .map(|&t| pool(t, &variants))
        .collect::<anyhow::Result<Vec<_>>>()?;
    // Every engine on every scene it takes, scene by scene (the others said why).
    let pairs: Vec<(&TraversalSetup, EngineVariant)> = setups
        .iter()
        .flat_map(|setup| variants.iter().map(move |&v| (setup, v)))
        .filter(|(setup, v)| match v.engine.takes_scene(&setup.scene) {
            Ok(()) => true,
            Err(na) => {
                eprintln!("note: {na}: no {} rows for {}", v.name(), setup.name);
                false
            }
        })
        .collect();
    anyhow::ensure!(!pairs.is_empty(), "no engine takes the scenes");
    for &engine in engines {
        let any_hit = setups
            .iter()
            .flat_map(|s| &s.kinds)
            .any(|set| set.kind.query() == Query::AnyHit);
        if let (Err(na), true) = (engine.finds_any_hit(), any_hit) {
            eprintln!("note: {na}: no {engine} rows for shadow or AO rays");
        }
    }
    // timings[t][c]: thread count t, scene and engine c.
    let mut timings: Vec<Vec<Timings>> = thread_counts
        .iter()
        .map(|_| {
            pairs
                .iter()
                .map(|(setup, _)| Timings::empty(setup.kinds.len()))
                .collect()
        })
        .collect();
    let structures = build_rounds(&pairs, engines, embree_isas, &thread_counts, &pools, &mut timings)?;
    let mut measured = engines_on_scenes(&pairs, structures)?;
    trace_rounds(&mut measured, &pools, rounds, hooks, &mut timings);
    rows(&measured, &timings, &thread_counts, rounds)
}

/// The thread counts of `threads`, each at least 1, once each in the order
/// given; an error when there is none.
fn distinct_thread_counts(threads: &[usize]) -> anyhow::Result<Vec<usize>> {
    let mut thread_counts: Vec<usize> = Vec::new();
    for t in threads.iter().map(|&t| t.max(1)) {
        if !thread_counts.contains(&t) {
            thread_counts.push(t);
        }
    }
    anyhow::ensure!(!thread_counts.is_empty(), "no thread count to measure");
    Ok(thread_counts)
}

/// Build the structure of every scene and engine of `pairs` on every thread
/// count (`pools[t]`, build times into `timings[t]`), round by round, an
/// untimed round then [`BUILD_ROUNDS`] timed ones, with a fresh [`Builder`]
/// per thread count and round, then once more, untimed, at the most threads.
/// Returns the structures of that last build, kept for tracing; every other
/// one is dropped before the next builder exists (it holds its device).
fn build_rounds<'a>(
    pairs: &[(&'a TraversalSetup, EngineVariant)],
    engines: &[Engine],
    embree_isas: &[EmbreeIsa],
    thread_counts: &[usize],
    pools: &[rayon::ThreadPool],
    timings: &mut [Vec<Timings>],
) -> anyhow::Result<Vec<Option<Built<'a>>>> {
    for round in 0..=BUILD_ROUNDS {
        for t in round_order(round, thread_counts.len()) {
            let builder = Builder::new(engines, embree_isas, thread_counts[t])?;
            pools[t].install(|| build_each(&builder, pairs, round, &mut timings[t], None))?;
        }
    }
    // The structures to trace come from one more build, untimed, at the most
    // threads, made last: while the last Embree device made has fewer
    // threads than an earlier one, a TBB worker spins (about three quarters
    // of a core) through every later round, which on a 2-vCPU machine took
    // up to a third of the 2-thread rounds, from either engine, at random.
    let most = (0..thread_counts.len())
        .max_by_key(|&t| thread_counts[t])
        .ok_or_else(|| anyhow::anyhow!("no thread count to build with"))?;
    let mut structures: Vec<Option<Built<'a>>> = pairs.iter().map(|_| None).collect();
    let builder = Builder::new(engines, embree_isas, thread_counts[most])?;
    pools[most].install(|| build_each(&builder, pairs, 0, &mut timings[most], Some(&mut structures[..])))?;
    Ok(structures)
}

/// Build the structure of every scene and engine of `pairs` with `builder` on
/// the current pool, in `round`'s order; past the untimed round 0 each is
/// built until its builds sum [`BUILD_SAMPLE`], and their mean time goes into
/// `timings`. The structures go into `kept` when given, else are dropped.
fn build_each<'a>(
    builder: &Builder,
    pairs: &[(&'a TraversalSetup, EngineVariant)],
    round: usize,
    timings: &mut [Timings],
    mut kept: Option<&mut [Option<Built<'a>>]>,
) -> anyhow::Result<()> {
    for c in round_order(round, pairs.len()) {
        let (setup, variant) = pairs[c];
        let (mut spent, mut builds) = (Duration::ZERO, 0u32);
        let structure = loop {
            let start = Instant::now();
            let structure = builder.build(variant, &setup.scene)?;
            spent += start.elapsed();
            builds += 1;
            if round == 0 || spent >= BUILD_SAMPLE {
                break structure;
            }
            drop(structure);
        };
        if round > 0 {
            timings[c]
                .build_ms
                .push(1e3 * spent.as_secs_f64() / f64::from(builds));
        }
        if let Some(kept) = kept.as_deref_mut() {
            kept[c] = Some(structure);
        }
    }
    Ok(())
}

/// Every scene and engine of `pairs` with its structure of `structures`, its
/// hits not yet counted; an error for one not built.
fn engines_on_scenes<'a>(
    pairs: &[(&'a TraversalSetup, EngineVariant)],
    structures: Vec<Option<Built<'a>>>,
) -> anyhow::Result<Vec<EngineOnScene<'a>>> {
    pairs
        .iter()
        .zip(structures)
        .map(|(&(setup, variant), structure)| {
            Ok(EngineOnScene {
                setup,
                variant,
                structure: structure.ok_or_else(|| anyhow::anyhow!("{} was not built", variant.name()))?,
                hits: vec![0; setup.kinds.len()],
            })
        })
        .collect()
}

/// Trace the rays of every scene and engine of `measured` on every thread
/// count (`pools[t]`, times into `timings[t]`), round by round through the
/// steps of thread count and scene and engine; round 0 warms every pool and
/// structure up (caches, page faults), counts the hits and is not kept, then
/// `rounds` rounds are timed.
fn trace_rounds(
    measured: &mut [EngineOnScene<'_>],
    pools: &[rayon::ThreadPool],
    rounds: usize,
    hooks: &TimingHooks,
    timings: &mut [Vec<Timings>],
) {
    let steps: Vec<(usize, usize)> = (0..pools.len())
        .flat_map(|t| (0..measured.len()).map(move |c| (t, c)))
        .collect();
    for round in 0..=rounds {
        for step in round_order(round, steps.len()) {
            let (t, c) = steps[step];
            let (on_scene, timing) = (&mut measured[c], &mut timings[t][c]);
            pools[t].install(|| trace_each_kind(on_scene, timing, round, hooks));
        }
    }
}

/// Trace every ray set of `on_scene` once on the current pool by each of
/// [`PATHS`] the engine has, times passing through `hooks`: round 0 counts
/// the hits of single rays, later rounds keep each time per ray in `timing`.
fn trace_each_kind(
    on_scene: &mut EngineOnScene<'_>,
    timing: &mut Timings,
    round: usize,
    hooks: &TimingHooks,
) {
    let engine = on_scene.variant.engine;
    // Only the queries the engine has (the rows leave the others out).
    let any_hit = engine.finds_any_hit().is_ok();
    for (k, set) in on_scene.setup.kinds.iter().enumerate() {
        if set.kind.query() == Query::AnyHit && !any_hit {
            continue;
        }
        // Packets only for an engine that traces them as such (its row leaves them out).
        for (p, &path) in PATHS.iter().enumerate() {
            if engine.traces_lanes(path.lanes()).is_err() {
                continue;
            }
            let start = Instant::now();
            let hits = black_box(on_scene.structure.visit(TraceKind { set, path }));
            let rays = set.rays.len() as f64;
            let seconds = hooks.apply(path_name(path), rays, start.elapsed().as_secs_f64());
            if round == 0 && path == KernelKind::Scalar {
                on_scene.hits[k] = hits;
            }
            if round > 0 {
                timing.per_ray[k][p].push(seconds / set.rays.len().max(1) as f64);
            }
        }
    }
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
        let [small, large] = setups.each_ref().map(|s| s.scene.primitives.len());
        assert!(small < large);
        assert_eq!(layout, [(2, small), (2, large), (1, small), (1, large)]);
        for row in &rows {
            assert_eq!(row.build_ms.samples, BUILD_ROUNDS, "{}", row.scene);
            for k in &row.kinds {
                let paths: Vec<&str> = k.paths.iter().map(|p| p.path).collect();
                assert_eq!(paths, ["single", "packet8", "packet16"]);
                assert!(k.paths.iter().all(|p| p.mrays.samples == 3));
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
