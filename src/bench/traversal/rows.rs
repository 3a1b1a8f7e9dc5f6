//! The traversal table: one row per scene, engine and thread count, with the
//! figures of each ray kind, made from the times of the measurement.

use crate::accel::{Accel, TraversalCounter, TraversalStats};
use crate::bench::figure::{Better, Figure};
use crate::bench::rays::{KindRays, Query, RayKind};
use crate::bench::traversal::engines::EngineVariant;
use crate::bench::traversal::measured::{EngineOnScene, Timings};
use crate::bench::traversal::trace::{PATHS, path_name};
use crate::embree_settings::EmbreeIsa;
use crate::engines::{Engine, WithAccel};
use crate::packet::RayPacket;
use crate::simd::SimdFloat;
use crate::statistics::{StatsError, Summary};

/// One row of the traversal table: a scene, an engine and a thread count.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TraversalRow {
    /// Scene name.
    pub scene: String,
    /// Primitives in the scene.
    pub primitives: usize,
    /// Engine whose structure was traversed.
    pub engine: Engine,
    /// Embree's ISA setting (None for raypack).
    pub embree_isa: Option<EmbreeIsa>,
    /// Threads of the rayon pool.
    pub threads: usize,
    /// Build time, ms: three samples, each the mean of a round's builds
    /// (see `measure::BUILD_SAMPLE`).
    pub build_ms: Summary,
    /// The tree's SAH cost (raypack only: Embree does not report its tree).
    pub sah_cost: Option<f64>,
    /// Primary rays: image size.
    pub resolution: (u32, u32),
    /// The figures of each ray kind, in the order measured.
    pub kinds: Vec<KindRow>,
    /// Timed rounds per variant.
    pub rounds: usize,
    /// raypack rows: build time over Embree's faster setting's (by medians),
    /// round by round, when Embree was measured alongside.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub build_vs_embree: Option<Summary>,
}

impl TraversalRow {
    /// The engine as measured (with Embree's ISA setting).
    pub fn variant(&self) -> EngineVariant {
        EngineVariant {
            engine: self.engine,
            embree_isa: self.embree_isa,
        }
    }

    /// The row's figures: build time, each kind's throughput by each path,
    /// packets over single rays, and the growth of time per ray from the first scene.
    pub fn figures(&self) -> Vec<Figure> {
        let labels = |extra: &[(&'static str, String)]| -> Vec<(&'static str, String)> {
            let mut l = vec![
                ("scene", self.scene.clone()),
                ("primitives", self.primitives.to_string()),
                ("engine", self.variant().name()),
                ("threads", self.threads.to_string()),
            ];
            l.extend_from_slice(extra);
            l
        };
        let mut figures = vec![Figure::new(
            "build",
            "ms",
            Better::Lower,
            &labels(&[]),
            self.build_ms,
        )];
        for k in &self.kinds {
            let kind = ("rays", k.kind.name().to_string());
            for p in &k.paths {
                let l = labels(&[kind.clone(), ("kernel", p.path.to_string())]);
                figures.push(Figure::new("throughput", "Mrays/s", Better::Higher, &l, p.mrays));
                figures.push(Figure::new(
                    "time per ray vs first scene",
                    "x",
                    Better::Neither,
                    &l,
                    p.growth_vs_first,
                ));
                if let Some(vs) = p.vs_embree {
                    figures.push(Figure::new("raypack/embree", "x", Better::Neither, &l, vs));
                }
            }
            for p in k.paths.iter().skip(1) {
                figures.push(Figure::new(
                    format!("{}/single", p.path),
                    "x",
                    Better::Neither,
                    &labels(std::slice::from_ref(&kind)),
                    p.vs_single,
                ));
            }
        }
        figures
    }
}

/// The figures of one ray kind in a [`TraversalRow`].
#[derive(Clone, Debug, serde::Serialize)]
pub struct KindRow {
    /// The kind.
    pub kind: RayKind,
    /// Its query.
    pub query: Query,
    /// Rays traced.
    pub rays: usize,
    /// Rays that hit (nearest) or found something (any hit), single-ray traversal.
    pub hits: u64,
    /// Each path the engine traced, in the order of [`PATHS`]: single rays
    /// first (every engine traces them), then the packets it has.
    pub paths: Vec<PathRow>,
    /// raypack rows: its fastest path against Embree's fastest path and
    /// setting on the same rays, when Embree was measured alongside.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub best_vs_embree: Option<BestVsEmbree>,
}

impl KindRow {
    /// The figures of the path named `name` (`packet8`…), if traced.
    pub fn path(&self, name: &str) -> Option<&PathRow> {
        self.paths.iter().find(|p| p.path == name)
    }

    /// The fastest path by median, Mrays/s, and which it was.
    pub fn best(&self) -> (f64, &'static str) {
        self.paths.iter().fold((0.0, "single"), |best, p| {
            if p.mrays.median > best.0 {
                (p.mrays.median, p.path)
            } else {
                best
            }
        })
    }
}

/// The figures of one path (single rays, 8- or 16-ray packets) of a [`KindRow`].
#[derive(Clone, Debug, serde::Serialize)]
pub struct PathRow {
    /// `single`, `packet8` or `packet16` ([`path_name`]).
    pub path: &'static str,
    /// Mrays/s.
    pub mrays: Summary,
    /// Mrays/s over single rays', round by round (1 for single rays).
    pub vs_single: Summary,
    /// Time per ray against the same engine, kind and path on the first
    /// scene measured alongside, round by round (1 for itself).
    pub growth_vs_first: Summary,
    /// raypack rows: Mrays/s over Embree's on the same path and rays (its
    /// first setting measured), round by round, when Embree was measured alongside.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vs_embree: Option<Summary>,
    /// Counts of one more, untimed pass (raypack only: Embree does not report them).
    pub stats: Option<TraversalStats>,
    /// Instructions per ray at one thread, counted by callgrind (`bench
    /// traversal --instructions`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instructions_per_ray: Option<f64>,
}

/// raypack's fastest path against Embree's fastest path and setting (each
/// by median Mrays/s) on the same rays: the comparison of issue 54's matrix.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BestVsEmbree {
    /// raypack's Mrays/s over Embree's, round by round.
    pub ratio: Summary,
    /// raypack's fastest path: `single`, `packet8` or `packet16`.
    pub raypack: &'static str,
    /// Embree's fastest setting and path: `embree(avx2) packet8`…
    pub embree: String,
}

/// The table: per thread count of `thread_counts`, whose figures are
/// `timings[t]`, a row for each scene and engine of `measured`, in order.
pub(super) fn rows(
    measured: &[EngineOnScene<'_>],
    timings: &[Vec<Timings>],
    thread_counts: &[usize],
    rounds: usize,
) -> anyhow::Result<Vec<TraversalRow>> {
    let mut rows = Vec::with_capacity(timings.len() * measured.len());
    for (of_threads, &threads) in timings.iter().zip(thread_counts) {
        for (on_scene, timing) in measured.iter().zip(of_threads) {
            // The engine's first scene: this one at the latest.
            let first = measured
                .iter()
                .position(|m| m.variant == on_scene.variant)
                .unwrap_or(0);
            // Embree on the same rays, each ISA setting measured, in order.
            let embree: Vec<(EngineVariant, &Timings)> = measured
                .iter()
                .zip(of_threads)
                .filter(|(m, _)| {
                    on_scene.variant.engine == Engine::Raypack
                        && m.variant.engine == Engine::Embree
                        && std::ptr::eq(m.setup, on_scene.setup)
                })
                .map(|(m, t)| (m.variant, t))
                .collect();
            rows.push(row(
                on_scene,
                timing,
                &of_threads[first].per_ray,
                &embree,
                threads,
                rounds,
            )?);
        }
    }
    Ok(rows)
}

/// The table row of `measured`: its times as Mrays/s, the ratios, the growth of
/// time per ray from `first_per_ray` (the engine's first scene, `timing`
/// being its own figures at the row's thread count), the speed
/// over Embree's on the same rays (`embree`: each setting measured, the
/// first for the path-by-path ratios; none when not measured), and for
/// raypack the SAH cost and the traversal counts of one more (untimed) pass of each path.
fn row(
    measured: &EngineOnScene<'_>,
    timing: &Timings,
    first_per_ray: &[[Vec<f64>; PATHS.len()]],
    embree: &[(EngineVariant, &Timings)],
    threads: usize,
    rounds: usize,
) -> anyhow::Result<TraversalRow> {
    let setup = measured.setup;
    let embree_per_ray = embree.first().map(|(_, e)| &e.per_ray[..]);
    let kinds = setup
        .kinds
        .iter()
        .enumerate()
        // A kind the engine has no query for was not traced: no row (the bench said why).
        .filter(|&(k, _)| traced(&timing.per_ray[k][0]))
        .map(|(k, set)| -> anyhow::Result<KindRow> {
            let times = &timing.per_ray[k];
            // Per kind, the first scene's sets are the same kinds in the same order.
            let first = first_per_ray.get(k).unwrap_or(times);
            let theirs = embree_per_ray.and_then(|e| e.get(k));
            let stats = measured.structure.visit(Counted(set));
            let paths = PATHS
                .iter()
                .enumerate()
                .filter(|&(p, _)| traced(&times[p]))
                .map(|(p, &path)| -> anyhow::Result<PathRow> {
                    Ok(PathRow {
                        path: path_name(path),
                        mrays: mrays(&times[p])?,
                        vs_single: Summary::paired_ratio(&times[0], &times[p])?,
                        growth_vs_first: Summary::paired_ratio(&times[p], &first[p])?,
                        vs_embree: theirs
                            .map(|e| &e[p])
                            .filter(|e| traced(e))
                            .map(|e| Summary::paired_ratio(e, &times[p]))
                            .transpose()?,
                        stats: stats.map(|s| s[p]),
                        instructions_per_ray: None,
                    })
                })
                .collect::<anyhow::Result<_>>()?;
            Ok(KindRow {
                kind: set.kind,
                query: set.kind.query(),
                rays: set.rays.len(),
                hits: measured.hits[k],
                paths,
                best_vs_embree: best_vs_embree(times, embree, k)?,
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let sah_cost = measured.structure.sah_cost();
    Ok(TraversalRow {
        scene: setup.name.clone(),
        primitives: setup.scene.id_count() as usize,
        engine: measured.variant.engine,
        embree_isa: measured.variant.embree_isa,
        threads,
        build_ms: Summary::of(&timing.build_ms)?,
        sah_cost,
        resolution: setup.resolution,
        kinds,
        rounds,
        build_vs_embree: build_vs_embree(&timing.build_ms, embree)?,
    })
}

/// Mrays/s of each round of `per_ray` (seconds per ray).
fn mrays(per_ray: &[f64]) -> Result<Summary, StatsError> {
    Summary::of(&per_ray.iter().map(|t| 1e-6 / t).collect::<Vec<_>>())
}

/// A path not traced (packets of a single-ray engine) has no times: no figure.
fn traced(per_ray: &[f64]) -> bool {
    !per_ray.is_empty()
}

/// The fastest of `paths` (a name and each round's seconds per ray) by
/// median Mrays/s; None when none was traced.
fn fastest<'t, N>(
    paths: impl IntoIterator<Item = (N, &'t [f64])>,
) -> Result<Option<(N, &'t [f64])>, StatsError> {
    let mut best: Option<(f64, N, &[f64])> = None;
    for (name, per_ray) in paths.into_iter().filter(|(_, t)| traced(t)) {
        let median = mrays(per_ray)?.median;
        if best.as_ref().is_none_or(|(m, _, _)| median > *m) {
            best = Some((median, name, per_ray));
        }
    }
    Ok(best.map(|(_, name, per_ray)| (name, per_ray)))
}

/// raypack's fastest path of `ours` (kind `k`'s times) against the fastest
/// path and setting of `embree` on the same kind; None without Embree.
fn best_vs_embree(
    ours: &[Vec<f64>; PATHS.len()],
    embree: &[(EngineVariant, &Timings)],
    k: usize,
) -> Result<Option<BestVsEmbree>, StatsError> {
    let theirs = embree.iter().flat_map(|(variant, t)| {
        PATHS
            .into_iter()
            .zip(&t.per_ray[k])
            .map(move |(path, per_ray)| ((*variant, path_name(path)), &per_ray[..]))
    });
    let ours = PATHS
        .into_iter()
        .map(path_name)
        .zip(ours.iter().map(Vec::as_slice));
    let (Some((path, ours)), Some(((variant, their_path), theirs))) = (fastest(ours)?, fastest(theirs)?)
    else {
        return Ok(None);
    };
    Ok(Some(BestVsEmbree {
        ratio: Summary::paired_ratio(theirs, ours)?,
        raypack: path,
        embree: format!("{} {their_path}", variant.name()),
    }))
}

/// raypack's build times `ours` over those of Embree's faster setting of
/// `embree` (by medians), round by round; None without Embree.
fn build_vs_embree(
    ours: &[f64],
    embree: &[(EngineVariant, &Timings)],
) -> Result<Option<Summary>, StatsError> {
    let mut faster: Option<(f64, &[f64])> = None;
    for (_, t) in embree {
        let median = Summary::of(&t.build_ms)?.median;
        if faster.is_none_or(|(m, _)| median < m) {
            faster = Some((median, &t.build_ms));
        }
    }
    faster
        .map(|(_, theirs)| Summary::paired_ratio(ours, theirs))
        .transpose()
}

/// The traversal counts of a kind's rays on a structure that counts its work
/// ([`Accel::COUNTS_WORK`]), by each of [`PATHS`]; None for one that does not.
struct Counted<'r>(&'r KindRays);

impl WithAccel<'_> for Counted<'_> {
    type Output = Option<[TraversalStats; PATHS.len()]>;

    fn run<A: Accel>(self, accel: &A) -> Self::Output {
        if !A::COUNTS_WORK {
            return None;
        }
        let set = self.0;
        let any_hit = set.kind.query() == Query::AnyHit;
        let mut stats: [TraversalCounter; PATHS.len()] = Default::default();
        for r in &set.rays {
            if any_hit {
                _ = accel.occluded_counted(r, &mut stats[0]);
            } else {
                _ = accel.intersect_counted(r, &mut stats[0]);
            }
        }
        count_packets(accel, &set.packets, any_hit, &mut stats[1]);
        count_packets(accel, &set.packets16, any_hit, &mut stats[2]);
        Some(stats.map(|s| *s.total()))
    }
}

/// Trace `packets` through `accel` with any-hit or nearest-hit queries,
/// counting the work into `stats`.
fn count_packets<A: Accel, F: SimdFloat>(
    accel: &A,
    packets: &[RayPacket<F>],
    any_hit: bool,
    stats: &mut TraversalCounter,
) {
    for p in packets {
        if any_hit {
            _ = accel.occluded_packet_counted(p, stats);
        } else {
            _ = accel.intersect_packet_counted(p, stats);
        }
    }
}
