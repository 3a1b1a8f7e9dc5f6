//! bvh (Rust, `bvh` feature) as a peer engine: its binary SAH BVH (built
//! with its rayon executor), walked by its `nearest_traverse_iterator`, which
//! hands out the primitives whose boxes a ray enters, nearest box first. The
//! crate has no two-sided triangle test (its `Ray::intersects_triangle` culls
//! back faces), so each candidate goes through raypack's scalar triangle test
//! (watertight), and the walk stops at the first box that starts beyond the
//! nearest hit: the comparison measures the crate's tree and walk. One ray at
//! a time; triangles and polygons only ([`TriangleSoup`](crate::engines::triangle_soup::TriangleSoup)).

use crate::engines::capabilities::Capabilities;

/// bvh in the registry.
pub struct BvhCrateEngine;

/// What bvh can do, linked or not.
const CAPABILITIES: Capabilities = Capabilities::SINGLE_RAY_TRIANGLES;

#[cfg(feature = "bvh")]
mod linked {
    use ::bvh::aabb::{Aabb, Bounded};
    use ::bvh::bounding_hierarchy::BHShape;
    use ::bvh::bvh::{Bvh, rayon_executor};
    use ::bvh::ray::Ray as BvhRay;
    use nalgebra::{Point3, Vector3};

    use crate::engines::bvh_binary::{BvhCrateEngine, CAPABILITIES};
    use crate::engines::capabilities::Capabilities;
    use crate::engines::engine_module::{Description, EngineModule, EngineOptions, WithAccel};
    use crate::engines::single_ray::{SingleRayQueries, SingleRays};
    use crate::engines::triangle_soup::TriangleSoup;
    use crate::geometry::Primitive;
    use crate::geometry::{Intersect, Triangle};
    use crate::ray::{Hit, Ray};

    /// One triangle as the crate's tree holds it: its box, its place in the
    /// scene's triangles, and the tree node the crate keeps for it (40 bytes).
    struct Shape {
        bounds: Aabb<f32, 3>,
        index: u32,
        node: usize,
    }

    impl Bounded<f32, 3> for Shape {
        fn aabb(&self) -> Aabb<f32, 3> {
            self.bounds
        }
    }

    impl BHShape<f32, 3> for Shape {
        fn set_bh_node_index(&mut self, node: usize) {
            self.node = node;
        }

        fn bh_node_index(&self) -> usize {
            self.node
        }
    }

    /// The crate's tree over a scene's triangles.
    pub struct BvhCrateScene {
        bvh: Bvh<f32, 3>,
        shapes: Vec<Shape>,
        /// raypack's triangle of each shape.
        triangles: Vec<Triangle>,
        /// The scene primitive of each shape.
        prims: Vec<u32>,
    }

    /// raypack's ray as the crate's.
    fn ray_of(ray: &Ray) -> BvhRay<f32, 3> {
        let (o, d) = (ray.origin, ray.dir);
        BvhRay::new(Point3::new(o.x, o.y, o.z), Vector3::new(d.x, d.y, d.z))
    }

    impl SingleRayQueries for BvhCrateScene {
        fn nearest(&self, ray: &Ray) -> Hit {
            let query = ray_of(ray);
            let mut hit = Hit::none(ray);
            for shape in self.bvh.nearest_traverse_iterator(&query, &self.shapes) {
                // Boxes come nearest entry first: past the nearest hit, nothing nearer is left.
                match query.intersection_slice_for_aabb(&shape.bounds) {
                    Some((entry, _)) if entry > hit.t => break,
                    _ => {}
                }
                let i = shape.index as usize;
                self.triangles[i].intersect(ray, self.prims[i], &mut hit);
            }
            hit
        }

        fn blocked(&self, ray: &Ray) -> bool {
            let query = ray_of(ray);
            self.bvh.traverse_iterator(&query, &self.shapes).any(|shape| {
                let i = shape.index as usize;
                self.triangles[i].intersect(ray, self.prims[i], &mut Hit::none(ray))
            })
        }
    }

    impl EngineModule for BvhCrateEngine {
        const NAME: &'static str = "bvh";
        const CAPABILITIES: Capabilities = CAPABILITIES;
        type Device = ();
        type Built<'p> = SingleRays<BvhCrateScene>;

        fn device(_: &EngineOptions) -> anyhow::Result<()> {
            Ok(())
        }

        fn build(_: &(), prims: &[Primitive]) -> anyhow::Result<SingleRays<BvhCrateScene>> {
            let soup = TriangleSoup::new(Self::NAME, prims)?;
            let triangles: Vec<Triangle> = soup
                .triangles
                .iter()
                .map(|&[a, b, c]| Triangle::new(a, b, c))
                .collect();
            let mut shapes: Vec<Shape> = triangles
                .iter()
                .zip(0u32..)
                .map(|(t, index)| {
                    let [a, b, c] = t.vertices();
                    let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                    Shape {
                        bounds: Aabb::with_bounds(
                            Point3::new(lo.x, lo.y, lo.z),
                            Point3::new(hi.x, hi.y, hi.z),
                        ),
                        index,
                        node: 0,
                    }
                })
                .collect();
            let bvh = Bvh::build_with_executor(&mut shapes, rayon_executor);
            Ok(SingleRays(BvhCrateScene {
                bvh,
                shapes,
                triangles,
                prims: soup.prims,
            }))
        }

        fn visit<'s, J: WithAccel<'s>>(built: &'s SingleRays<BvhCrateScene>, job: J) -> J::Output {
            job.run(built)
        }

        fn describe(built: &SingleRays<BvhCrateScene>) -> Description {
            Description {
                structure: "bvh2",
                settings: format!(
                    "bvh {}, binary SAH BVH, {} nodes, raypack's triangle test, single rays",
                    crate::environment::peer_version("bvh"),
                    built.0.bvh.nodes.len()
                ),
                translation: None,
            }
        }
    }
}

#[cfg(not(feature = "bvh"))]
crate::engines::unavailable::not_linked!(BvhCrateEngine, "bvh", CAPABILITIES, feature = "bvh");
