//! The traversal table: one row per scene, engine and thread count, with the
//! figures of each ray kind, made from the times of the measurement.

use crate::accel::{Accel, TraversalCounter, TraversalStats};
use crate::bench::figure::{Better, Figure};
use crate::bench::rays::{KindRays, Query, RayKind};
use crate::bench::traversal::engines::EngineVariant;
use crate::bench::traversal::measured::{EngineOnScene, Timings};
use crate::embree_settings::EmbreeIsa;
use crate::engines::{Engine, WithAccel};
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

    /// The row's figures: build time, each kind's single-ray and packet
    /// throughput, their ratio, and the growth of time per ray from the first scene.
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
            // The paths the engine traced (packets: not for a single-ray engine).
            let paths = [("single", Some(k.single_mrays)), ("packet8", k.packet_mrays)];
            for (v, (kernel, s)) in paths.into_iter().enumerate() {
                let (Some(s), Some(growth)) = (s, k.growth_vs_first[v]) else {
                    continue;
                };
                let l = labels(&[kind.clone(), ("kernel", kernel.to_string())]);
                figures.push(Figure::new("throughput", "Mrays/s", Better::Higher, &l, s));
                figures.push(Figure::new(
                    "time per ray vs first scene",
                    "x",
                    Better::Neither,
                    &l,
                    growth,
                ));
                if let Some(vs) = k.vs_embree {
                    figures.push(Figure::new("raypack/embree", "x", Better::Neither, &l, vs[v]));
                }
            }
            if let Some(ratio) = k.packet_vs_single {
                figures.push(Figure::new(
                    "packet8/single",
                    "x",
                    Better::Neither,
                    &labels(&[kind]),
                    ratio,
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
    /// Single-ray traversal, Mrays/s.
    pub single_mrays: Summary,
    /// 8-ray packets, Mrays/s (None for an engine that traces single rays only).
    pub packet_mrays: Option<Summary>,
    /// `packet_mrays / single_mrays`, round by round.
    pub packet_vs_single: Option<Summary>,
    /// Counts of the single-ray pass (raypack only: Embree does not report them).
    pub single_stats: Option<TraversalStats>,
    /// Counts of the packet pass (raypack only).
    pub packet_stats: Option<TraversalStats>,
    /// Time per ray against the same engine and kind on the first scene
    /// measured alongside, round by round (1 for itself): single rays, packets
    /// (None where not traced).
    pub growth_vs_first: [Option<Summary>; 2],
    /// raypack rows: Mrays/s over Embree's on the same rays, round by round,
    /// when Embree was measured alongside: single rays, packets.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vs_embree: Option<[Summary; 2]>,
    /// raypack rows: its fastest path against Embree's fastest path and
    /// setting on the same rays, when Embree was measured alongside.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub best_vs_embree: Option<BestVsEmbree>,
    /// Instructions per ray at one thread, counted by callgrind (`bench
    /// traversal --instructions`): single rays, packets (None where not traced).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub instructions_per_ray: Option<[Option<f64>; 2]>,
}

impl KindRow {
    /// The faster of single rays and packets by median, Mrays/s, and which it was.
    pub fn best(&self) -> (f64, &'static str) {
        match self.packet_mrays {
            Some(packet) if packet.median > self.single_mrays.median => (packet.median, "packet8"),
            _ => (self.single_mrays.median, "single"),
        }
    }
}

/// raypack's fastest path against Embree's fastest path and setting (each
/// by median Mrays/s) on the same rays: the comparison of issue 54's matrix.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BestVsEmbree {
    /// raypack's Mrays/s over Embree's, round by round.
    pub ratio: Summary,
    /// raypack's fastest path: `single` or `packet8`.
    pub raypack: &'static str,
    /// Embree's fastest setting and path: `embree(avx2) packet8`…
    pub embree: String,
}

/// The names of a kind's two paths, in the order of its times.
const PATHS: [&str; 2] = ["single", "packet8"];

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
/// raypack the SAH cost and the traversal counts of one more (untimed) pass of each variant.
fn row(
    measured: &EngineOnScene<'_>,
    timing: &Timings,
    first_per_ray: &[[Vec<f64>; 2]],
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
            let [single, packet] = &timing.per_ray[k];
            // Per kind, the first scene's sets are the same kinds in the same order.
            let first = first_per_ray.get(k).unwrap_or(&timing.per_ray[k]);
            let stats = measured.structure.visit(Counted(set));
            Ok(KindRow {
                kind: set.kind,
                query: set.kind.query(),
                rays: set.rays.len(),
                hits: measured.hits[k],
                single_mrays: mrays(single)?,
                packet_mrays: traced(packet).then(|| mrays(packet)).transpose()?,
                packet_vs_single: traced(packet)
                    .then(|| Summary::paired_ratio(single, packet))
                    .transpose()?,
                single_stats: stats.map(|[single, _]| single),
                packet_stats: stats.map(|[_, packet]| packet),
                growth_vs_first: [
                    Some(Summary::paired_ratio(single, &first[0])?),
                    traced(packet)
                        .then(|| Summary::paired_ratio(packet, &first[1]))
                        .transpose()?,
                ],
                vs_embree: match embree_per_ray.and_then(|e| e.get(k)) {
                    Some([e_single, e_packet]) => Some([
                        Summary::paired_ratio(e_single, single)?,
                        Summary::paired_ratio(e_packet, packet)?,
                    ]),
                    None => None,
                },
                best_vs_embree: best_vs_embree(&timing.per_ray[k], embree, k)?,
                instructions_per_ray: None,
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
    ours: &[Vec<f64>; 2],
    embree: &[(EngineVariant, &Timings)],
    k: usize,
) -> Result<Option<BestVsEmbree>, StatsError> {
    let theirs = embree.iter().flat_map(|(variant, t)| {
        PATHS
            .into_iter()
            .zip(&t.per_ray[k])
            .map(move |(path, per_ray)| ((*variant, path), &per_ray[..]))
    });
    let ours = PATHS.into_iter().zip(ours.iter().map(Vec::as_slice));
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
/// ([`Accel::COUNTS_WORK`]): single rays, packets; None for one that does not.
struct Counted<'r>(&'r KindRays);

impl WithAccel<'_> for Counted<'_> {
    type Output = Option<[TraversalStats; 2]>;

    fn run<A: Accel>(self, accel: &A) -> Self::Output {
        if !A::COUNTS_WORK {
            return None;
        }
        let set = self.0;
        let mut stats: [TraversalCounter; 2] = Default::default();
        for r in &set.rays {
            match set.kind.query() {
                Query::Nearest => _ = accel.intersect_counted(r, &mut stats[0]),
                Query::AnyHit => _ = accel.occluded_counted(r, &mut stats[0]),
            }
        }
        for p in &set.packets {
            match set.kind.query() {
                Query::Nearest => _ = accel.intersect_packet_counted(p, &mut stats[1]),
                Query::AnyHit => _ = accel.occluded_packet_counted(p, &mut stats[1]),
            }
        }
        Some(stats.map(|s| *s.total()))
    }
}
