//! The engine registry: every engine a ray query can go through, in one list.
//!
//! An engine is one module that says what it can do ([`Capabilities`]), makes
//! its device once per run ([`EngineModule::device`]: Embree's `RTCDevice`,
//! raypack's choice of structure) and builds its structure over a scene's
//! primitives ([`EngineModule::build`]). The `registry!` line at
//! the bottom of this file turns the list into the [`Engine`] choice of the
//! command line, the [`EngineDevice`] and [`Built`] values that hold any
//! engine's device and structure, and the dispatch between them. `render`,
//! `bench`, `check` and `trace` ask these and nothing else.
//!
//! Work on a built structure goes through [`Built::visit`] with a
//! [`WithAccel`] job, so the job is compiled for each engine's [`Accel`](crate::accel::Accel)
//! type: the match on the engine happens once per job, never per ray.
//!
//! Adding an engine: write its module (an [`EngineModule`]), and add one line
//! to the registry.

pub mod bvh_binary;
mod capabilities;
pub mod embree;
mod engine_module;
pub mod obvhs_cwbvh;
pub mod raypack;
mod registry;
pub mod single_ray;
pub mod tinybvh;
pub mod triangle_soup;
mod unavailable;

pub use capabilities::{Capabilities, PrimitiveKinds};
pub use engine_module::{Description, EngineModule, EngineOptions, WithAccel};
pub use unavailable::Unavailable;

use crate::geometry::Primitive;
use crate::scene::Scene;

registry::registry! {
    /// raypack's own kernels and acceleration structure.
    Raypack => raypack::RaypackEngine,
    /// Embree 4 (needs the `embree` feature).
    Embree => embree::EmbreeEngine,
    /// obvhs, its compressed 8-wide BVH (needs the `obvhs` feature).
    Obvhs => obvhs_cwbvh::ObvhsEngine,
    /// bvh, its binary SAH BVH (needs the `bvh` feature).
    Bvh => bvh_binary::BvhCrateEngine,
    /// tinybvh, its binary BVH (needs the `tinybvh` feature).
    Tinybvh => tinybvh::TinybvhEngine,
    /// tinybvh, its BVH8_CPU (needs the `tinybvh` feature and AVX2 in the Rust build).
    Tinybvh8 => tinybvh::TinybvhBvh8Engine,
}

/// Why an engine cannot do what was asked: a command refuses it (the user's
/// to change, exit 2), a bench leaves the cell out and says why.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("n/a: {0}")]
pub struct NotApplicable(pub String);

impl Engine {
    /// Whether the engine traces `lanes` rays together (1: single rays; 8 or
    /// 16: packets) as such, not lane by lane.
    pub fn traces_lanes(self, lanes: usize) -> Result<(), NotApplicable> {
        let c = self.capabilities();
        match lanes {
            1 => Ok(()),
            8 if c.packet8 => Ok(()),
            16 if c.packet16 => Ok(()),
            _ => Err(NotApplicable(format!(
                "{self} traces single rays only, not {lanes}-wide packets (ask for single rays: --kernel scalar)"
            ))),
        }
    }

    /// Whether the engine has an any-hit (occlusion) query of its own: one
    /// without it is n/a for shadow and AO rays, never timed through its
    /// nearest-hit query instead.
    pub fn finds_any_hit(self) -> Result<(), NotApplicable> {
        if self.capabilities().any_hit {
            return Ok(());
        }
        Err(NotApplicable(format!(
            "{self} has no any-hit (occlusion) query, which shadow and AO rays need"
        )))
    }

    /// Whether the engine takes every primitive of `prims`.
    pub fn takes(self, prims: &[Primitive]) -> Result<(), NotApplicable> {
        self.takes_each(prims.iter())
    }

    /// Whether the engine takes every primitive of `scene`, its meshes' included.
    pub fn takes_scene(self, scene: &Scene) -> Result<(), NotApplicable> {
        let meshes = scene.instances.meshes().iter().flat_map(|m| &m.primitives);
        self.takes_each(scene.primitives.iter().chain(meshes))
    }

    /// Whether the engine takes every primitive of `prims`.
    fn takes_each<'p>(self, prims: impl Iterator<Item = &'p Primitive>) -> Result<(), NotApplicable> {
        let others = match self.capabilities().primitives {
            PrimitiveKinds::All => 0,
            PrimitiveKinds::Triangles => prims
                .filter(|p| !matches!(p, Primitive::Triangle(_) | Primitive::Polygon(_)))
                .count(),
        };
        if others == 0 {
            return Ok(());
        }
        Err(NotApplicable(format!(
            "{self} takes triangles and polygons only; the scene has {}",
            crate::plural::count(others as u64, "other primitive", "other primitives")
        )))
    }

    /// Run every engine of `engines`' thread setup ([`EngineModule::thread_start`])
    /// on each thread of `pool` and on the calling thread, before any of them traces.
    pub fn prepare_threads(engines: &[Engine], pool: &rayon::ThreadPool) {
        let start = || engines.iter().for_each(|e| e.thread_start());
        pool.broadcast(|_| start());
        start();
    }
}

impl EngineDevice {
    /// Build the structure over `scene` ([`build_scene`](Self::build_scene)),
    /// with the seconds it took.
    pub fn build_timed<'p>(&self, scene: &'p Scene) -> anyhow::Result<(Built<'p>, f64)> {
        let start = std::time::Instant::now();
        let built = self.build_scene(scene)?;
        Ok((built, start.elapsed().as_secs_f64()))
    }
}

/// Make `engine`'s device with `options`, build it over `prims` and run `job`
/// with the structure; returns the job's output and the build's seconds
/// (device included: what a user waits for before the first ray).
pub fn with_engine<O, J: for<'s> WithAccel<'s, Output = O>>(
    engine: Engine,
    options: &EngineOptions,
    prims: &[Primitive],
    job: J,
) -> anyhow::Result<(O, f64)> {
    let start = std::time::Instant::now();
    let built = engine.device(options)?.build(prims)?;
    let seconds = start.elapsed().as_secs_f64();
    Ok((built.visit(job), seconds))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{Accel, AccelKind};
    use crate::geometry::sphere::Sphere;
    use crate::ray::Ray;
    use glam::Vec3;

    /// A job that traces one ray and says whether the engine counts its work.
    struct OneRay(Ray);

    impl WithAccel<'_> for OneRay {
        type Output = (Option<u32>, bool);
        fn run<A: Accel>(self, accel: &A) -> Self::Output {
            let hit = accel.intersect(&self.0);
            (hit.is_hit().then_some(hit.prim), A::COUNTS_WORK)
        }
    }

    #[test]
    fn names_parse_back_to_their_engines() {
        use clap::ValueEnum;
        for &engine in Engine::ALL {
            assert_eq!(Engine::from_str(engine.name(), false), Ok(engine));
            assert_eq!(engine.to_possible_value().unwrap().get_name(), engine.name());
        }
        assert_eq!(Engine::ALL.len(), Engine::value_variants().len());
    }

    #[test]
    fn raypack_builds_either_structure_and_each_finds_the_sphere() {
        let prims = [
            Primitive::Sphere(Sphere::new(Vec3::new(0.0, 0.0, -5.0), 1.0)),
            Primitive::Sphere(Sphere::new(Vec3::new(3.0, 0.0, -5.0), 1.0)),
        ];
        let ray = Ray::unbounded(Vec3::ZERO, Vec3::NEG_Z);
        for accel in [AccelKind::None, AccelKind::Bvh] {
            let options = EngineOptions {
                accel,
                ..EngineOptions::default()
            };
            let device = Engine::Raypack.device(&options).unwrap();
            let built = device.build(&prims).unwrap();
            assert_eq!(built.engine(), Engine::Raypack);
            assert_eq!(built.describe().structure, accel.name());
            assert_eq!(built.visit(OneRay(ray)), (Some(0), true), "{accel}");
        }
    }

    #[test]
    fn embree_is_built_or_says_how_to_get_it() {
        let prims = [Primitive::Sphere(Sphere::new(Vec3::new(0.0, 0.0, -5.0), 1.0))];
        let ray = Ray::unbounded(Vec3::ZERO, Vec3::NEG_Z);
        let result = with_engine(Engine::Embree, &EngineOptions::default(), &prims, OneRay(ray));
        if cfg!(feature = "embree") {
            let ((hit, counts), _) = result.unwrap();
            assert_eq!((hit, counts), (Some(0), false));
        } else {
            let e = result.expect_err("no Embree in this build");
            assert!(e.to_string().contains("--features embree"), "{e}");
        }
    }

    /// Each ray's nearest primitive (None for a miss) and whether it is blocked.
    struct Answers<'r>(&'r [Ray]);

    impl WithAccel<'_> for Answers<'_> {
        type Output = Vec<(Option<u32>, bool)>;
        fn run<A: Accel>(self, accel: &A) -> Self::Output {
            self.0
                .iter()
                .map(|r| {
                    let hit = accel.intersect(r);
                    (hit.is_hit().then_some(hit.prim), accel.occluded(r))
                })
                .collect()
        }
    }

    #[test]
    fn every_engine_in_this_build_agrees_with_brute_force_on_random_triangles() {
        use crate::scene::generate::random::random_triangles;
        let prims = random_triangles(2000, 7);
        let mut rng = crate::rng::Rng::new(8);
        // From around the triangles (in [-1, 1]³) towards a point among them.
        let mut point = || rng.point_in(Vec3::splat(-1.5), Vec3::splat(1.5));
        let rays: Vec<Ray> = (0..4000)
            .map(|_| {
                let (from, to) = (point(), point());
                Ray::unbounded(from, (to - from).normalize_or(Vec3::X))
            })
            .collect();
        let reference = EngineOptions {
            accel: AccelKind::None,
            ..EngineOptions::default()
        };
        let (expected, _) = with_engine(Engine::Raypack, &reference, &prims, Answers(&rays)).unwrap();
        let hits = expected.iter().filter(|(p, _)| p.is_some()).count();
        assert!(hits > 400 && hits < 3600, "{hits} of the rays hit");
        for &engine in Engine::ALL.iter().filter(|e| e.linked()) {
            let (answers, _) =
                with_engine(engine, &EngineOptions::default(), &prims, Answers(&rays)).unwrap();
            // Rays that graze an edge may go either way; anything else must not.
            let differ = answers.iter().zip(&expected).filter(|(a, b)| a != b).count();
            assert!(differ <= 2, "{engine}: {differ} of {} rays differ", rays.len());
            for (nearest, blocked) in &answers {
                assert_eq!(
                    nearest.is_some(),
                    *blocked,
                    "{engine}: an unbounded ray is blocked iff it hits"
                );
            }
        }
    }
}
