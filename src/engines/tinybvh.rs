//! tinybvh (C++, Jacco Bikker; the `tinybvh-rs` crate, `tinybvh` feature)
//! as two peer engines, one ray at a time over the scene's triangles
//! ([`TriangleSoup`](crate::engines::triangle_soup::TriangleSoup)):
//!
//! - `tinybvh`: its `BVH` (Wald's 32-byte binary nodes), built by its binned
//!   SAH builder (`BVH::Build`, one thread), traversed by `BVH::Intersect`
//!   (nearest child first, Möller–Trumbore triangles). That test takes a
//!   determinant below 10⁻⁶ *absolute* for a ray parallel to the triangle, so
//!   it misses triangles of small area whatever the angle (the dragon at its
//!   own scale, edges about 2·10⁻⁴: 43% of random rays; scaled ×100: none).
//! - `tinybvh8`: its `BVH8_CPU` (the 8-wide layout of Fuetterling et al. 2017,
//!   "Accelerated single ray tracing for wide vector units"), converted from
//!   that tree with leaves of at most four triangles, traversed by
//!   `BVH8_CPU::Intersect` (AVX2). tinybvh-rs binds that traversal only in
//!   builds whose Rust code has AVX2 (`-C target-feature=+avx2,+fma`);
//!   without it the engine says so.
//!
//! Both: nearest hits only (tinybvh-rs binds no occlusion query, so shadow and
//! AO rays are n/a), and no `t_min` (a ray's origin is moved to
//! `origin + t_min·dir` instead). tinybvh-rs compiles tinybvh with
//! `-march=native`; `.cargo/config.toml` makes that x86-64-v3, so a build
//! with this feature runs on any AVX2 machine (and under valgrind).

use crate::engines::capabilities::Capabilities;

/// tinybvh's binary BVH in the registry.
pub struct TinybvhEngine;

/// tinybvh's BVH8_CPU in the registry.
pub struct TinybvhBvh8Engine;

/// What either tinybvh engine can do, linked or not.
const CAPABILITIES: Capabilities = Capabilities {
    any_hit: false,
    t_min: false,
    ..Capabilities::SINGLE_RAY_TRIANGLES
};

#[cfg(feature = "tinybvh")]
mod linked {
    use glam::Vec3;
    use tinybvh_rs::{Intersector, bvh};

    use crate::engines::capabilities::Capabilities;
    use crate::engines::engine_module::{Description, EngineModule, EngineOptions, WithAccel};
    use crate::engines::single_ray::{SingleRayQueries, SingleRays};
    use crate::engines::tinybvh::{CAPABILITIES, TinybvhEngine};
    use crate::engines::triangle_soup::TriangleSoup;
    use crate::geometry::Primitive;
    use crate::ray::{Hit, Ray};

    /// tinybvh's "no hit yet" distance (`BVH_FAR`).
    const FAR: f32 = tinybvh_rs::INFINITE;

    /// tinybvh's `Ray` as its C++ lays it out (128 bytes, 64-byte aligned:
    /// tinybvh 1.6.8 with 32 instance-index bits). tinybvh-rs's `Ray` is only
    /// its first 64 bytes, which the C++ code reads and writes at the same
    /// offsets (origin, mask, direction, instance, inverse direction, then the
    /// hit's instance at 44 and `t, u, v, prim` at 48..64); the C++ `Ray`
    /// goes on with 64 bytes of user data, so the ray handed over must own
    /// them too. (tinybvh-rs's `Ray::new` returns a C++ `Ray` by value into
    /// 64 bytes: not used here.)
    #[repr(C, align(64))]
    struct CppRay {
        /// The fields tinybvh-rs names.
        ray: tinybvh_rs::Ray,
        /// The C++ hit record's user data, unused.
        _user: [u8; 64],
    }

    const _: () = assert!(size_of::<CppRay>() == 128 && align_of::<CppRay>() == 64);
    const _: () = assert!(std::mem::offset_of!(tinybvh_rs::Ray, hit) == 48);

    /// tinybvh's safe reciprocal (`tinybvh_safercp`): ±[`FAR`] for a zero
    /// component, as its own `Ray` constructor computes the inverse direction.
    #[inline]
    fn safe_rcp(x: f32) -> f32 {
        if x.abs() > 1e-12 {
            1.0 / x
        } else if x >= 0.0 {
            FAR
        } else {
            -FAR
        }
    }

    /// `ray` for tinybvh, which has no `t_min`: its origin moved to
    /// `origin + t_min·dir`, `t_max` shortened to match (and capped at
    /// [`FAR`]). None for a ray tinybvh must not see: NaN input ends the
    /// process there (its `VALIDATE_RAY`), and an empty interval finds nothing.
    #[inline]
    fn cpp_ray(ray: &Ray) -> Option<CppRay> {
        let origin = ray.origin + ray.t_min * ray.dir;
        let t_max = (ray.t_max - ray.t_min).min(FAR);
        if !(origin.is_finite() && ray.dir.is_finite() && t_max > 0.0) {
            return None;
        }
        let rcp = ray.dir.to_array().map(safe_rcp);
        let mut hit = tinybvh_rs::Intersection::new();
        hit.t = t_max;
        Some(CppRay {
            ray: tinybvh_rs::Ray {
                origin: origin.to_array(),
                // The C++ `mask`: every geometry (`RAY_MASK_INTERSECT_ALL`).
                padding_0: 0xFFFF,
                dir: ray.dir.to_array(),
                // The C++ `instIdx`.
                padding_1: 0,
                r_d: rcp,
                // The C++ hit's `inst`.
                padding_2: 0,
                hit,
            },
            _user: [0; 64],
        })
    }

    /// The nearest hit of `ray` through `intersect` (one of tinybvh's
    /// `Intersect`s), its primitive named by `prims` (the scene primitive of
    /// each triangle).
    #[inline]
    fn nearest(ray: &Ray, prims: &[u32], intersect: impl FnOnce(&mut tinybvh_rs::Ray)) -> Hit {
        let mut found = Hit::none(ray);
        let Some(mut cpp) = cpp_ray(ray) else {
            return found;
        };
        let t_max = cpp.ray.hit.t;
        intersect(&mut cpp.ray);
        let hit = cpp.ray.hit;
        if hit.t < t_max {
            found.record(hit.t + ray.t_min, prims[hit.prim as usize], hit.u, hit.v);
        }
        found
    }

    /// The scene's triangles as tinybvh takes them: three `[x, y, z, 0]` per
    /// triangle, in the soup's order.
    fn positions(soup: &TriangleSoup) -> Vec<[f32; 4]> {
        let corner = |v: Vec3| [v.x, v.y, v.z, 0.0];
        soup.triangles.iter().flat_map(|t| t.map(corner)).collect()
    }

    /// One of tinybvh's trees over a scene's triangles: `T` the tree type.
    pub struct TinyScene<T> {
        /// The tree (None over no triangles: tinybvh has no empty tree);
        /// declared before `positions`, so dropped first.
        tree: Option<T>,
        /// The triangles' corners, for a tree that reads them in place (the
        /// binary BVH borrows them: a `Vec`'s heap block stays where it is
        /// when the struct moves); empty for one that copied them.
        _positions: Vec<[f32; 4]>,
        /// The scene primitive of each triangle.
        prims: Vec<u32>,
    }

    /// tinybvh's binary BVH over a scene's triangles, which it reads in place.
    pub type WaldScene = TinyScene<bvh::BVH<'static>>;

    // SAFETY: tinybvh's `Intersect` members are `const`: they read the tree
    // (and the positions) and write only the ray they are given; nothing
    // mutates a tree after its build, so threads may share it and move it.
    unsafe impl<T: Intersector> Send for TinyScene<T> {}
    // SAFETY: as for `Send`: shared use is reads only.
    unsafe impl<T: Intersector> Sync for TinyScene<T> {}

    impl<T: Intersector> SingleRayQueries for TinyScene<T> {
        fn nearest(&self, ray: &Ray) -> Hit {
            match &self.tree {
                Some(tree) => nearest(ray, &self.prims, |r| {
                    tree.intersect(r);
                }),
                None => Hit::none(ray),
            }
        }

        /// The nearest hit, found or not: commands show any-hit work as n/a
        /// for tinybvh ([`CAPABILITIES`]), so this answers, and is never timed.
        fn blocked(&self, ray: &Ray) -> bool {
            self.nearest(ray).is_hit()
        }
    }

    impl EngineModule for TinybvhEngine {
        const NAME: &'static str = "tinybvh";
        const CAPABILITIES: Capabilities = CAPABILITIES;
        type Device = ();
        type Built<'p> = SingleRays<WaldScene>;

        fn device(_: &EngineOptions) -> anyhow::Result<()> {
            Ok(())
        }

        fn build(_: &(), prims: &[Primitive]) -> anyhow::Result<SingleRays<WaldScene>> {
            let soup = TriangleSoup::new(Self::NAME, prims)?;
            let positions = positions(&soup);
            // SAFETY: the slice lives in `positions`' heap block, which the
            // scene owns and drops after the tree (field order) and never changes.
            let view: &'static [[f32; 4]] =
                unsafe { std::slice::from_raw_parts(positions.as_ptr(), positions.len()) };
            // tinybvh has no tree over no triangles.
            let bvh = (!view.is_empty())
                .then(|| bvh::BVH::new(view.into()))
                .transpose()
                .map_err(|e| anyhow::anyhow!("tinybvh: {e}"))?;
            Ok(SingleRays(TinyScene {
                tree: bvh,
                _positions: positions,
                prims: soup.prims,
            }))
        }

        fn visit<'s, J: WithAccel<'s>>(built: &'s SingleRays<WaldScene>, job: J) -> J::Output {
            job.run(built)
        }

        fn describe(built: &SingleRays<WaldScene>) -> Description {
            Description {
                structure: "bvh2",
                settings: format!(
                    "tinybvh-rs {} (tinybvh 1.6.8), BVH (Wald layout) from its binned SAH build, {} nodes, single rays, nearest hits only, t_min as a moved origin",
                    crate::environment::peer_version("tinybvh-rs"),
                    built.0.tree.as_ref().map_or(0, |b| b.nodes().len())
                ),
                translation: None,
            }
        }
    }

    #[cfg(target_feature = "avx2")]
    mod bvh8 {
        use tinybvh_rs::{bvh, bvh8_cpu, mbvh};

        use crate::engines::capabilities::Capabilities;
        use crate::engines::engine_module::{Description, EngineModule, EngineOptions, WithAccel};
        use crate::engines::single_ray::SingleRays;
        use crate::engines::tinybvh::linked::{TinyScene, positions};
        use crate::engines::tinybvh::{CAPABILITIES, TinybvhBvh8Engine};
        use crate::engines::triangle_soup::TriangleSoup;
        use crate::geometry::Primitive;

        /// tinybvh's BVH8_CPU over a scene's triangles (which it copies into
        /// its leaves: the binary tree and the positions it came from go).
        pub type Bvh8Scene = TinyScene<bvh8_cpu::BVH>;

        impl EngineModule for TinybvhBvh8Engine {
            const NAME: &'static str = "tinybvh8";
            const CAPABILITIES: Capabilities = CAPABILITIES;
            type Device = ();
            type Built<'p> = SingleRays<Bvh8Scene>;

            fn device(_: &EngineOptions) -> anyhow::Result<()> {
                Ok(())
            }

            fn build(_: &(), prims: &[Primitive]) -> anyhow::Result<SingleRays<Bvh8Scene>> {
                let soup = TriangleSoup::new(Self::NAME, prims)?;
                let positions = positions(&soup);
                let bvh = if positions.is_empty() {
                    None
                } else {
                    // BVH8_CPU takes an 8-wide tree with at most 4 triangles a leaf.
                    let mut binary = bvh::BVH::new(positions.as_slice().into())
                        .map_err(|e| anyhow::anyhow!("tinybvh8: {e}"))?;
                    binary.split_leaves(4);
                    let wide = mbvh::BVH::new(&binary);
                    Some(bvh8_cpu::BVH::new(&wide).map_err(|e| anyhow::anyhow!("tinybvh8: {e}"))?)
                };
                Ok(SingleRays(TinyScene {
                    tree: bvh,
                    _positions: Vec::new(),
                    prims: soup.prims,
                }))
            }

            fn visit<'s, J: WithAccel<'s>>(built: &'s SingleRays<Bvh8Scene>, job: J) -> J::Output {
                job.run(built)
            }

            fn describe(_: &SingleRays<Bvh8Scene>) -> Description {
                Description {
                    structure: "bvh8",
                    settings: format!(
                        "tinybvh-rs {} (tinybvh 1.6.8), BVH8_CPU from its binned SAH build (leaves of ≤ 4), AVX2, single rays, nearest hits only, t_min as a moved origin",
                        crate::environment::peer_version("tinybvh-rs"),
                    ),
                    translation: None,
                }
            }
        }
    }
}

#[cfg(not(feature = "tinybvh"))]
crate::engines::unavailable::not_linked!(TinybvhEngine, "tinybvh", CAPABILITIES, feature = "tinybvh");

#[cfg(not(feature = "tinybvh"))]
crate::engines::unavailable::not_linked!(TinybvhBvh8Engine, "tinybvh8", CAPABILITIES, feature = "tinybvh");

#[cfg(all(feature = "tinybvh", not(target_feature = "avx2")))]
crate::engines::unavailable::not_linked!(
    TinybvhBvh8Engine,
    "tinybvh8",
    CAPABILITIES,
    message = "tinybvh8 (tinybvh's BVH8_CPU) needs AVX2 in the Rust build: tinybvh-rs binds its traversal \
               only then; build with `RUSTFLAGS='-C target-feature=+avx2,+fma' cargo build --release \
               --features tinybvh` (a binary for AVX2 machines)"
);

#[cfg(all(test, feature = "tinybvh"))]
mod tests {
    use glam::Vec3;

    use crate::accel::{Accel, AccelKind};
    use crate::engines::engine_module::{EngineModule, EngineOptions, WithAccel};
    use crate::engines::raypack::RaypackEngine;
    use crate::engines::tinybvh::{TinybvhBvh8Engine, TinybvhEngine};
    use crate::geometry::{Primitive, Triangle};
    use crate::ray::{Hit, Ray};

    /// Each ray's hit record.
    struct Hits<'r>(&'r [Ray]);

    impl WithAccel<'_> for Hits<'_> {
        type Output = Vec<Hit>;
        fn run<A: Accel>(self, accel: &A) -> Self::Output {
            self.0.iter().map(|r| accel.intersect(r)).collect()
        }
    }

    /// Engine `E`'s hits of `rays` over `prims` with `options`, named by the
    /// engine; None where this build has not got it.
    fn hits_of<E: EngineModule>(
        options: &EngineOptions,
        prims: &[Primitive],
        rays: &[Ray],
    ) -> Option<(&'static str, Vec<Hit>)> {
        if !E::LINKED {
            return None;
        }
        let device = E::device(options).unwrap();
        let built = E::build(&device, prims).unwrap();
        Some((E::NAME, E::visit(&built, Hits(rays))))
    }

    /// Both tinybvh engines' hits, where this build has them.
    fn tinybvh_hits(prims: &[Primitive], rays: &[Ray]) -> Vec<(&'static str, Vec<Hit>)> {
        let options = EngineOptions::default();
        [
            hits_of::<TinybvhEngine>(&options, prims, rays),
            hits_of::<TinybvhBvh8Engine>(&options, prims, rays),
        ]
        .into_iter()
        .flatten()
        .collect()
    }

    #[test]
    fn hits_come_back_through_the_cpp_ray_layout_as_raypack_finds_them() {
        // Two squares of two triangles facing the rays, at z = -2 and z = -5,
        // a sphere-free scene whose primitive 4 is a degenerate triangle
        // (dropped by the soup: the numbering must survive it).
        let square = |z: f32| {
            let (a, b, c, d) = (
                Vec3::new(-1.0, -1.0, z),
                Vec3::new(1.0, -1.0, z),
                Vec3::new(1.0, 1.0, z),
                Vec3::new(-1.0, 1.0, z),
            );
            [Triangle::new(a, b, c), Triangle::new(a, c, d)]
        };
        let mut prims: Vec<Primitive> = square(-5.0).into_iter().map(Primitive::Triangle).collect();
        prims.push(Primitive::Triangle(Triangle::new(
            Vec3::ZERO,
            Vec3::X,
            Vec3::X * 2.0,
        )));
        prims.extend(square(-2.0).into_iter().map(Primitive::Triangle));
        let from = Vec3::new(0.3, -0.2, 0.0);
        let rays = [
            // The near square.
            Ray::unbounded(from, Vec3::NEG_Z),
            // Past the near square by t_min: the far one (t counted from the origin).
            Ray::new(from, Vec3::NEG_Z, 3.0, f32::INFINITY),
            // Stopping short of the near square.
            Ray::new(from, Vec3::NEG_Z, 0.0, 1.5),
            // Slanted, into the other triangle of the near square.
            Ray::unbounded(Vec3::new(-0.5, 0.6, 0.0), Vec3::new(-0.1, 0.1, -1.0).normalize()),
            // Away from everything; in the near square's plane (two zero
            // components of the direction: tinybvh's safe reciprocal).
            Ray::unbounded(from, Vec3::Z),
            Ray::unbounded(Vec3::new(5.0, 0.0, -2.0), Vec3::NEG_X),
            // NaN and infinite input: tinybvh would end the process on NaN.
            Ray::unbounded(Vec3::splat(f32::NAN), Vec3::NEG_Z),
            Ray::unbounded(from, Vec3::new(f32::NAN, 0.0, -1.0)),
            Ray::unbounded(Vec3::new(0.0, 0.0, f32::INFINITY), Vec3::NEG_Z),
        ];
        let reference = EngineOptions {
            accel: AccelKind::None,
            ..EngineOptions::default()
        };
        let (_, expected) = hits_of::<RaypackEngine>(&reference, &prims, &rays).unwrap();
        assert_eq!(
            expected.iter().map(|h| h.is_hit()).collect::<Vec<_>>(),
            [true, true, false, true, false, false, false, false, false],
            "raypack: {expected:?}"
        );
        for (engine, hits) in tinybvh_hits(&prims, &rays) {
            for ((hit, want), ray) in hits.iter().zip(&expected).zip(&rays) {
                assert_eq!(hit.prim, want.prim, "{engine}: {ray:?}");
                if want.is_hit() {
                    assert!((hit.t - want.t).abs() < 1e-5, "{engine}: {hit:?} {want:?}");
                    let point = |h: &Hit| {
                        let [a, b, c] = match &prims[h.prim as usize] {
                            Primitive::Triangle(t) => t.vertices(),
                            _ => unreachable!("triangles only"),
                        };
                        a * (1.0 - h.u - h.v) + b * h.u + c * h.v
                    };
                    assert!(
                        point(hit).distance(point(want)) < 1e-5,
                        "{engine}: {hit:?} {want:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn no_triangles_no_hits() {
        let ray = Ray::unbounded(Vec3::ZERO, Vec3::NEG_Z);
        for (engine, hits) in tinybvh_hits(&[], &[ray]) {
            assert!(!hits[0].is_hit(), "{engine}");
        }
    }
}
