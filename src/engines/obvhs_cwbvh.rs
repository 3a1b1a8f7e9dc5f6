//! obvhs (Rust, `obvhs` feature) as a peer engine: its compressed 8-wide BVH
//! (CWBVH, Ylitie, Karras and Laine 2017: 80-byte nodes, child boxes
//! quantised to 8 bits) built from a binary PLOC tree (Meister and Bittner
//! 2018) at its `medium_build` preset, the preset of its own examples;
//! traversed by its `ray_traverse` (nearest) and `ray_traverse_miss` (any
//! hit) with its two-sided Möller–Trumbore triangle test, one ray at a time.
//! Triangles and polygons only ([`TriangleSoup`](crate::engines::triangle_soup::TriangleSoup)).

use crate::engines::capabilities::Capabilities;

/// obvhs in the registry.
pub struct ObvhsEngine;

/// What obvhs can do, linked or not.
const CAPABILITIES: Capabilities = Capabilities::SINGLE_RAY_TRIANGLES;

#[cfg(feature = "obvhs")]
mod linked {
    use std::time::Duration;

    use ::obvhs::BvhBuildParams;
    use ::obvhs::cwbvh::CwBvh;
    use ::obvhs::cwbvh::builder::build_cwbvh_from_tris;
    use ::obvhs::ray::{Ray as ObvhsRay, RayHit};
    use ::obvhs::triangle::Triangle as ObvhsTriangle;

    use crate::engines::capabilities::Capabilities;
    use crate::engines::engine_module::{Description, EngineModule, EngineOptions, WithAccel};
    use crate::engines::obvhs_cwbvh::{CAPABILITIES, ObvhsEngine};
    use crate::engines::single_ray::{SingleRayQueries, SingleRays};
    use crate::engines::triangle_soup::TriangleSoup;
    use crate::geometry::Primitive;
    use crate::ray::{Hit, Ray};

    /// obvhs's tree over a scene, with its triangles in the tree's order.
    pub struct ObvhsScene {
        /// The CWBVH.
        bvh: CwBvh,
        /// Triangle `i` of the tree's order (48 bytes: three `Vec3A`).
        triangles: Vec<ObvhsTriangle>,
        /// The scene primitive of each triangle of `triangles`.
        prims: Vec<u32>,
    }

    /// raypack's ray as obvhs's (which precomputes the inverse direction).
    #[inline]
    fn ray_of(ray: &Ray) -> ObvhsRay {
        ObvhsRay::new(ray.origin.into(), ray.dir.into(), ray.t_min, ray.t_max)
    }

    impl SingleRayQueries for ObvhsScene {
        fn nearest(&self, ray: &Ray) -> Hit {
            let mut found = RayHit::none();
            let triangles = &self.triangles;
            if !self
                .bvh
                .ray_traverse(ray_of(ray), &mut found, |r, i| triangles[i].intersect(r))
            {
                return Hit::none(ray);
            }
            let i = found.primitive_id as usize;
            let uv = triangles[i].compute_barycentric(&ray_of(ray));
            let mut hit = Hit::none(ray);
            hit.record(found.t, self.prims[i], uv.x, uv.y);
            hit
        }

        fn blocked(&self, ray: &Ray) -> bool {
            let triangles = &self.triangles;
            !self
                .bvh
                .ray_traverse_miss(ray_of(ray), |r, i| triangles[i].intersect(r))
        }
    }

    impl EngineModule for ObvhsEngine {
        const NAME: &'static str = "obvhs";
        const CAPABILITIES: Capabilities = CAPABILITIES;
        type Device = ();
        type Built<'p> = SingleRays<ObvhsScene>;

        fn device(_: &EngineOptions) -> anyhow::Result<()> {
            Ok(())
        }

        fn build(_: &(), prims: &[Primitive]) -> anyhow::Result<SingleRays<ObvhsScene>> {
            let soup = TriangleSoup::new(Self::NAME, prims)?;
            let triangles: Vec<ObvhsTriangle> = soup
                .triangles
                .iter()
                .map(|&[a, b, c]| ObvhsTriangle {
                    v0: a.into(),
                    v1: b.into(),
                    v2: c.into(),
                })
                .collect();
            let mut core_build_time = Duration::ZERO;
            let bvh = build_cwbvh_from_tris(&triangles, BvhBuildParams::medium_build(), &mut core_build_time);
            // The leaves name triangles by their place in the tree's order: lay them out so.
            let order = &bvh.primitive_indices;
            Ok(SingleRays(ObvhsScene {
                triangles: order.iter().map(|&i| triangles[i as usize]).collect(),
                prims: order.iter().map(|&i| soup.prims[i as usize]).collect(),
                bvh,
            }))
        }

        fn visit<'s, J: WithAccel<'s>>(built: &'s SingleRays<ObvhsScene>, job: J) -> J::Output {
            job.run(built)
        }

        fn describe(built: &SingleRays<ObvhsScene>) -> Description {
            Description {
                structure: "cwbvh",
                settings: format!(
                    "obvhs {}, CWBVH from PLOC (medium_build), {} nodes, single rays",
                    crate::environment::peer_version("obvhs"),
                    built.0.bvh.nodes.len()
                ),
                translation: None,
            }
        }
    }
}

#[cfg(not(feature = "obvhs"))]
crate::engines::unavailable::not_linked!(ObvhsEngine, "obvhs", CAPABILITIES, feature = "obvhs");
