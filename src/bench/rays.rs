//! The standard ray kinds a renderer traces, as the field measures traversal
//! (Aila & Laine, "Understanding the efficiency of ray traversal on GPUs",
//! HPG 2009): coherent `primary` rays, `shadow` and ambient-occlusion (`ao`)
//! any-hit rays, `diffuse` bounce rays and uniformly `random` rays.
//!
//! Every kind is made once, before timing, from a seed, so every engine traces
//! the same rays. Primary rays go through pixel centres in 16×16 tiles of
//! 4×4-pixel blocks, each one 16-wide packet or two 8-wide ones (4×2 pixels);
//! the secondary kinds start at the primary hit points (found with raypack's
//! BVH, untimed), one ray per hit, and are packed as their primary rays are: a
//! packet holds the secondary rays of its pixels, its lanes whose primary ray
//! missed inactive. Their origins are pushed off the surface along the facing
//! normal by the scene's [`epsilon_for`], which is also their `t_min`.

use glam::Vec3;

use crate::accel::{Accel, Bvh, TwoLevel};
use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::huge_pages::ADVISED_BYTES;
use crate::packet::{RayPacket, RayPacket8, RayPacket16};
use crate::ray::Ray;
use crate::render::batch::BATCH;
use crate::render::whitted::epsilon_for;
use crate::rng::Rng;
use crate::scene::Scene;

/// A standard kind of ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RayKind {
    /// Camera rays through pixel centres (nearest hit).
    Primary,
    /// From the primary hit points to a light (any hit).
    Shadow,
    /// Ambient occlusion: cosine-distributed about the facing normal, of length
    /// a tenth of the scene box's diagonal (`AO_LENGTH`; any hit).
    Ao,
    /// Diffuse bounces: cosine-distributed about the facing normal, unbounded (nearest hit).
    Diffuse,
    /// From uniform points of the scene box in uniform directions (nearest hit).
    Random,
}

/// Length of ambient-occlusion rays, as a fraction of the scene box's diagonal.
pub const AO_LENGTH: f32 = 0.1;

impl RayKind {
    /// Every kind, in report order.
    pub const ALL: [RayKind; 5] = [Self::Primary, Self::Shadow, Self::Ao, Self::Diffuse, Self::Random];

    /// The name in reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Primary => "primary",
            Self::Shadow => "shadow",
            Self::Ao => "ao",
            Self::Diffuse => "diffuse",
            Self::Random => "random",
        }
    }

    /// The query rays of this kind ask.
    pub fn query(self) -> Query {
        match self {
            Self::Shadow | Self::Ao => Query::AnyHit,
            Self::Primary | Self::Diffuse | Self::Random => Query::Nearest,
        }
    }
}

/// What a ray asks of the structure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Query {
    /// The nearest hit (`intersect`, `rtcIntersect*`).
    Nearest,
    /// Whether anything is hit (`occluded`, `rtcOccluded*`).
    AnyHit,
}

/// Rays per block: the renderer's batch, a 16-wide packet or two 8-wide ones.
const BLOCK: usize = BATCH;

/// A block's rays and the mask of those that take part.
type Block = ([Ray; BLOCK], u32);

/// The rays of one kind, one by one and in 8- and 16-ray packets (the same rays).
#[derive(Clone, Debug)]
pub struct KindRays {
    /// Their kind.
    pub kind: RayKind,
    /// The rays, packet by packet in lane order.
    pub rays: Vec<Ray>,
    /// The same rays in 8-ray packets (inactive lanes where a block has fewer).
    pub packets: Vec<RayPacket8>,
    /// The same rays in 16-ray packets: each block whole.
    pub packets16: Vec<RayPacket16>,
}

impl KindRays {
    /// The rays of `kind` from blocks of up to 16 rays.
    fn from_blocks(kind: RayKind, blocks: impl IntoIterator<Item = Block>) -> Self {
        let mut set = Self {
            kind,
            rays: Vec::new(),
            packets: Vec::new(),
            packets16: Vec::new(),
        };
        for (lanes, mask) in blocks {
            if mask == 0 {
                continue;
            }
            set.rays
                .extend((0..BLOCK).filter(|i| mask & (1 << i) != 0).map(|i| lanes[i]));
            for (half, rays) in lanes.chunks(8).enumerate() {
                let half_mask = mask >> (8 * half) & 0xff;
                if half_mask != 0 {
                    set.packets.push(RayPacket8::from_rays_masked(rays, half_mask));
                }
            }
            set.packets16.push(RayPacket16::from_rays_masked(&lanes, mask));
        }
        set.on_huge_pages()
    }

    /// The rays of `kind` from `rays` in order, packed as they come.
    fn from_rays(kind: RayKind, rays: Vec<Ray>) -> Self {
        fn packed<F: crate::simd::SimdFloat>(rays: &[Ray]) -> Vec<RayPacket<F>> {
            rays.chunks(F::LANES).map(RayPacket::from_rays).collect()
        }
        Self {
            kind,
            packets: packed(&rays),
            packets16: packed(&rays),
            rays,
        }
        .on_huge_pages()
    }

    /// These rays with room for at least [`ADVISED_BYTES`] in each array, so
    /// that a binary on [`HugePageAlloc`](crate::huge_pages::HugePageAlloc)
    /// holds every set on huge pages, however few its rays. The timing loops
    /// read a set over and over, and on the VMs this project measures on,
    /// sets on 4 KiB pages from `malloc` traced several times slower, for
    /// every engine, most of the time spent on the first load of each ray
    /// (docs/measurements.md, "Constants").
    fn on_huge_pages(mut self) -> Self {
        fn reserve<T>(v: &mut Vec<T>) {
            let least = ADVISED_BYTES.div_ceil(size_of::<T>().max(1));
            v.reserve_exact(least.saturating_sub(v.len()));
        }
        reserve(&mut self.rays);
        reserve(&mut self.packets);
        reserve(&mut self.packets16);
        self
    }
}

/// Where the standard kinds start: the scene, its camera and light.
pub struct RaySource<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Their box (bounded primitives).
    pub bounds: Aabb,
    /// The camera of the primary rays.
    pub camera: &'a Camera,
    /// The light of the shadow rays: the scene's first, or [`default_light`].
    pub light: Vec3,
    /// Random rays to make.
    pub random: usize,
    /// Seed of every random choice.
    pub seed: u64,
}

/// A light for scenes without one: above the middle of `bounds`, one diagonal higher.
pub fn default_light(bounds: Aabb) -> Vec3 {
    let c = bounds.center();
    Vec3::new(c.x, bounds.max.y + bounds.extent().length(), c.z)
}

impl RaySource<'_> {
    /// The rays of each of `kinds`, in that order.
    pub fn make(&self, kinds: &[RayKind]) -> Vec<KindRays> {
        let blocks = self.primary_blocks();
        let needs_hits = kinds
            .iter()
            .any(|k| !matches!(k, RayKind::Primary | RayKind::Random));
        let surfaces = if needs_hits {
            self.surfaces(&blocks)
        } else {
            Vec::new()
        };
        let eps = epsilon_for(self.bounds, self.camera.eye);
        kinds
            .iter()
            .map(|&kind| match kind {
                RayKind::Primary => KindRays::from_blocks(kind, blocks.iter().copied()),
                RayKind::Random => KindRays::from_rays(
                    kind,
                    crate::compare::ray_sets::uniform_rays(self.bounds, self.random, self.seed),
                ),
                RayKind::Shadow | RayKind::Ao | RayKind::Diffuse => {
                    // One generator per kind, so a kind's rays do not depend on the others asked for.
                    let mut rng = Rng::new(self.seed ^ (kind as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
                    let ao_length = AO_LENGTH * self.bounds.extent().length();
                    let blocks = surfaces.iter().map(|block| {
                        let mut mask = 0;
                        let lanes = std::array::from_fn(|i| match block[i] {
                            Some((p, n)) => {
                                mask |= 1 << i;
                                let origin = p + eps * n;
                                match kind {
                                    RayKind::Shadow => {
                                        let to_light = self.light - origin;
                                        let distance = to_light.length();
                                        Ray::new(origin, to_light / distance, eps, distance)
                                    }
                                    RayKind::Ao => {
                                        Ray::new(origin, cosine_direction(n, &mut rng), eps, ao_length)
                                    }
                                    _ => Ray::new(origin, cosine_direction(n, &mut rng), eps, f32::INFINITY),
                                }
                            }
                            None => Ray::new(Vec3::ZERO, Vec3::Z, 0.0, 0.0),
                        });
                        (lanes, mask)
                    });
                    KindRays::from_blocks(kind, blocks)
                }
            })
            .collect()
    }

    /// The primary rays of the camera, tile by tile, 4×4-pixel block by block.
    fn primary_blocks(&self) -> Vec<Block> {
        let camera = self.camera;
        let (w, h) = (camera.width, camera.height);
        let mut blocks = Vec::with_capacity((w * h) as usize / BLOCK);
        for ty in (0..h).step_by(16) {
            for tx in (0..w).step_by(16) {
                for py in (ty..(ty + 16).min(h)).step_by(4) {
                    for px in (tx..(tx + 16).min(w)).step_by(4) {
                        let mut mask = 0;
                        let lanes = std::array::from_fn(|k| {
                            let (i, j) = (px + k as u32 % 4, py + k as u32 / 4);
                            if i < w && j < h {
                                mask |= 1 << k;
                                camera.pixel_ray(i, j)
                            } else {
                                Ray::new(Vec3::ZERO, Vec3::Z, 0.0, 0.0)
                            }
                        });
                        blocks.push((lanes, mask));
                    }
                }
            }
        }
        blocks
    }

    /// Per primary ray of each block: its hit point and the normal facing it, if it hit.
    fn surfaces(&self, blocks: &[Block]) -> Vec<[Option<(Vec3, Vec3)>; BLOCK]> {
        if self.scene.instances.is_empty() {
            self.surfaces_through(&Bvh::new(&self.scene.primitives), blocks)
        } else {
            self.surfaces_through(&TwoLevel::new(self.scene, Bvh::new), blocks)
        }
    }

    /// [`surfaces`](Self::surfaces), the primary rays traced through `accel`.
    fn surfaces_through<A: Accel>(&self, accel: &A, blocks: &[Block]) -> Vec<[Option<(Vec3, Vec3)>; BLOCK]> {
        use rayon::prelude::*;
        blocks
            .par_iter()
            .map(|(lanes, mask)| {
                std::array::from_fn(|i| {
                    if mask & (1 << i) == 0 {
                        return None;
                    }
                    let ray = &lanes[i];
                    let hit = accel.intersect(ray);
                    if !hit.is_hit() {
                        return None;
                    }
                    let (n, _) = self.scene.normals_at(ray, &hit);
                    let n = if n.dot(ray.dir) > 0.0 { -n } else { n };
                    Some((ray.at(hit.t), n)).filter(|(p, n)| p.is_finite() && n.is_normalized())
                })
            })
            .collect()
    }
}

/// A direction about the unit normal `n`, with density proportional to the
/// cosine of its angle to `n` (Malley's method: a uniform point of the unit
/// disc lifted onto the hemisphere).
pub fn cosine_direction(n: Vec3, rng: &mut Rng) -> Vec3 {
    let (u1, u2) = (rng.f32(), rng.f32());
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    let (a, b) = n.any_orthonormal_pair();
    let d = r * phi.cos() * a + r * phi.sin() * b + (1.0 - u1).max(0.0).sqrt() * n;
    d.normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_packs_its_rays_in_order() {
        let prims = crate::scene::generate::random::bumpy_sphere(500, 1);
        let scene = crate::scene::generate::test_scenes::scene_of("bumpy".into(), prims);
        let bounds = crate::bench::traversal::scene_bounds(&scene);
        let camera = crate::scene::generate::random::framing_camera(bounds, 40, 20);
        let source = RaySource {
            scene: &scene,
            bounds,
            camera: &camera,
            light: default_light(bounds),
            random: 100,
            seed: 2,
        };
        let sets = source.make(&RayKind::ALL);
        assert_eq!(sets[0].rays.len(), 800);
        assert_eq!(sets[4].packets.len(), 13);
        assert_eq!(sets[4].packets16.len(), 7);
        // 40 × 20 pixels: 10 × 5 blocks of 4×4, each one 16-wide packet or two 8-wide ones.
        assert_eq!(sets[0].packets16.len(), 50);
        assert_eq!(sets[0].packets.len(), 100);
        for set in &sets {
            let lanes8 = set
                .packets
                .iter()
                .flat_map(|p| (0..8).filter(|&i| p.is_active(i)).map(|i| p.ray(i)));
            assert!(lanes8.eq(set.rays.iter().copied()), "{:?}", set.kind);
            let lanes16 = set
                .packets16
                .iter()
                .flat_map(|p| (0..16).filter(|&i| p.is_active(i)).map(|i| p.ray(i)));
            assert!(lanes16.eq(set.rays.iter().copied()), "{:?}", set.kind);
        }
        // The secondary kinds start at the primary hits, and some primary rays miss.
        for set in &sets[1..4] {
            assert!(!set.rays.is_empty() && set.rays.len() < 800, "{:?}", set.kind);
            assert!(set.rays.iter().all(|r| r.dir.is_normalized() && r.t_min > 0.0));
        }
    }
}
