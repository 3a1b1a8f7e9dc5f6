//! Instructions per ray of the traversal bench (`--instructions`): the same
//! command runs again under callgrind ([`callgrind`]), builds the same
//! structures over the same rays, and traces each ray set once per engine
//! and path on one thread, between a reset of callgrind's counts and a dump
//! named for the set ([`count_instructions`]); [`instructions_per_ray`] puts
//! the counts on the rows of the timed run.

use std::hint::black_box;

use crate::bench::callgrind;
use crate::bench::rays::{Query, RayKind};
use crate::bench::traversal::engines::{Builder, EngineVariant, TraceKind, engine_variants, pool};
use crate::bench::traversal::rows::TraversalRow;
use crate::bench::traversal::setup::TraversalSetup;
use crate::bench::traversal::trace::{PATHS, path_name};
use crate::embree_settings::EmbreeIsa;
use crate::engines::Engine;

/// The name of the dump of scene `setup`'s `kind` rays through `variant` by `path`.
fn label(setup: usize, variant: EngineVariant, kind: RayKind, path: &str) -> String {
    format!("{setup}/{}/{}/{path}", variant.name(), kind.name())
}

/// In the run under callgrind: trace every ray set of `setups` once through
/// each engine of `engines` (Embree at each of `embree_isas`) that takes it,
/// by each of [`PATHS`] the engine has, on one thread, each
/// between [`callgrind::zero_stats`] and a [`callgrind::dump_stats_at`] named
/// for it. Builds and ray making are not counted.
pub fn count_instructions(
    setups: &[TraversalSetup],
    engines: &[Engine],
    embree_isas: &[EmbreeIsa],
) -> anyhow::Result<()> {
    let variants = engine_variants(engines, embree_isas)?;
    let pool = pool(1, &variants)?;
    let builder = Builder::new(engines, embree_isas, 1)?;
    for (s, setup) in setups.iter().enumerate() {
        for &variant in variants
            .iter()
            .filter(|v| v.engine.takes_scene(&setup.scene).is_ok())
        {
            let built = pool.install(|| builder.build(variant, &setup.scene))?;
            let engine = variant.engine;
            for set in &setup.kinds {
                if set.kind.query() == Query::AnyHit && engine.finds_any_hit().is_err() {
                    continue;
                }
                for path in PATHS
                    .into_iter()
                    .filter(|p| engine.traces_lanes(p.lanes()).is_ok())
                {
                    pool.install(|| {
                        callgrind::zero_stats();
                        black_box(built.visit(TraceKind { set, path }));
                        callgrind::dump_stats_at(&label(s, variant, set.kind, path_name(path)));
                    });
                }
            }
        }
    }
    Ok(())
}

/// Put on `rows` (of the timed run over `setups`) the instructions per ray
/// of each of their kinds and paths, from the run under callgrind's `counts`
/// (label and instructions, as [`count_instructions`] made them).
pub fn instructions_per_ray(rows: &mut [TraversalRow], setups: &[TraversalSetup], counts: &[(String, u64)]) {
    for row in rows {
        let Some(s) = setups.iter().position(|setup| setup.name == row.scene) else {
            continue;
        };
        let variant = row.variant();
        for k in &mut row.kinds {
            let (kind, rays) = (k.kind, k.rays as u64);
            for p in &mut k.paths {
                p.instructions_per_ray = callgrind::per_ray(counts, &label(s, variant, kind, p.path), rays);
            }
        }
    }
}
