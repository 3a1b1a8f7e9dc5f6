//! Kernel throughput: ray-primitive tests per second of each shape's scalar and
//! packet kernels on the same rays, shared by `raypack bench kernels` and the
//! criterion bench `benches/kernels.rs`.
//!
//! Each setup aims random rays from a sphere around the shape at random points
//! of a box a little larger than the shape, so about half of them hit: neither
//! kernel is measured on its early-out path alone.

use std::hint::black_box;
use std::time::{Duration, Instant};

use glam::{Mat4, Quat, Vec3};
use wide::{f32x4, f32x8, f32x16};

use crate::bench::figure::{Better, Figure};
use crate::bench::timing_hooks::TimingHooks;

use crate::geometry::plane::Plane;
use crate::geometry::{Cone, Intersect, Polygon, Primitive, Sphere, Transformed, Triangle};
use crate::packet::{HitPacket, RayPacket};
use crate::ray::{Hit, Ray};
use crate::rng::Rng;
use crate::simd::isa::{Level, LevelTask};
use crate::simd::{Isa, SimdFloat};
use crate::statistics::Summary;

/// One shape and the rays it is measured on.
pub struct KernelSetup<K> {
    /// Name in reports (`sphere`, `plane`, …).
    pub name: &'static str,
    /// The shape.
    pub kernel: K,
    /// The rays.
    pub rays: Vec<Ray>,
}

impl<K: Intersect> KernelSetup<K> {
    /// The rays packed `F::LANES` at a time.
    pub fn packets<F: SimdFloat>(&self) -> Vec<RayPacket<F>> {
        self.rays.chunks(F::LANES).map(RayPacket::from_rays).collect()
    }

    /// Fraction of rays that hit the shape.
    pub fn hit_rate(&self) -> f64 {
        let hits = self
            .rays
            .iter()
            .filter(|r| self.kernel.intersect(r, 0, &mut Hit::none(r)))
            .count();
        hits as f64 / self.rays.len() as f64
    }
}

/// Something that wants every kernel setup (they have different types, so the
/// list is walked with a visitor rather than returned).
pub trait SetupVisitor {
    /// Called once per setup, in report order.
    fn visit<K: Intersect>(&mut self, setup: &KernelSetup<K>);
}

/// Rays from a sphere of radius `distance` around `target`'s centre towards
/// random points of `target`, `n` of them.
pub fn aimed_rays(rng: &mut Rng, lo: Vec3, hi: Vec3, distance: f32, n: usize) -> Vec<Ray> {
    let center = 0.5 * (lo + hi);
    (0..n)
        .map(|_| {
            let origin = center + distance * rng.unit_vector();
            let aim = rng.point_in(lo, hi);
            Ray::unbounded(origin, (aim - origin).normalize())
        })
        .collect()
}

/// A concave ten-pointed star in the plane z = 0.3·x, radii 1 and 0.4.
pub fn star_polygon() -> Polygon {
    let vertices: Vec<Vec3> = (0..10)
        .map(|i| {
            let r = if i % 2 == 0 { 1.0 } else { 0.4 };
            let a = i as f32 * std::f32::consts::TAU / 10.0;
            let (x, y) = (r * a.cos(), r * a.sin());
            Vec3::new(x, y, 0.3 * x)
        })
        .collect();
    Polygon::new(&vertices).expect("the star is a valid polygon")
}

/// Visit every kernel setup with `n` rays each, from `seed`.
pub fn for_each_setup(n: usize, seed: u64, visitor: &mut impl SetupVisitor) {
    let mut rng = Rng::new(seed);
    let unit = Vec3::splat(1.25);
    let mut rays = |lo: Vec3, hi: Vec3| aimed_rays(&mut rng, lo, hi, 6.0, n);

    visitor.visit(&KernelSetup {
        name: "sphere",
        kernel: Sphere::new(Vec3::ZERO, 1.0),
        rays: rays(-unit, unit),
    });
    let plane_box = (Vec3::new(-1.0, -1.0, -2.0), Vec3::new(1.0, 1.0, 2.0));
    let tilted = Vec3::new(0.2, 0.3, 1.0);
    visitor.visit(&KernelSetup {
        name: "plane",
        kernel: Plane::implicit(tilted.x, tilted.y, tilted.z, 0.1).expect("valid plane"),
        rays: rays(plane_box.0, plane_box.1),
    });
    visitor.visit(&KernelSetup {
        name: "plane_point_normal",
        kernel: Plane::point_normal(Vec3::new(0.0, 0.0, -0.1), tilted).expect("valid plane"),
        rays: rays(plane_box.0, plane_box.1),
    });
    visitor.visit(&KernelSetup {
        name: "plane_parametric",
        kernel: Plane::parametric(Vec3::ZERO, Vec3::new(1.0, 0.0, -0.2), Vec3::new(0.0, 1.0, -0.3))
            .expect("valid plane"),
        rays: rays(plane_box.0, plane_box.1),
    });
    visitor.visit(&KernelSetup {
        name: "triangle",
        kernel: Triangle::new(
            Vec3::new(-1.0, -1.0, 0.2),
            Vec3::new(1.0, -1.0, -0.2),
            Vec3::new(0.0, 1.0, 0.0),
        ),
        rays: rays(Vec3::new(-1.0, -1.0, -0.2), Vec3::new(1.0, 1.0, 0.2)),
    });
    visitor.visit(&KernelSetup {
        name: "polygon",
        kernel: star_polygon(),
        rays: rays(Vec3::new(-1.0, -1.0, -0.3), Vec3::new(1.0, 1.0, 0.3)),
    });
    let cone =
        Cone::new(Vec3::new(-0.2, -1.0, 0.1), 1.0, Vec3::new(0.2, 1.0, -0.1), 0.4).expect("valid cone");
    visitor.visit(&KernelSetup {
        name: "cone",
        rays: rays(cone.bounds().min, cone.bounds().max),
        kernel: cone,
    });
    let ellipsoid = Mat4::from_scale_rotation_translation(
        Vec3::new(1.0, 0.5, 0.25),
        Quat::from_rotation_z(0.5),
        Vec3::new(0.1, 0.0, 0.0),
    );
    visitor.visit(&KernelSetup {
        name: "transformed",
        kernel: Transformed::new(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)), ellipsoid)
            .expect("invertible transform"),
        rays: rays(-unit, unit),
    });
}

/// Run the scalar kernel over all rays once; returns a checksum so nothing is optimised away.
#[inline(never)]
pub fn run_scalar<K: Intersect>(kernel: &K, rays: &[Ray]) -> f32 {
    struct Task<'a, K>(&'a K, &'a [Ray]);
    impl<K: Intersect> LevelTask for Task<'_, K> {
        type Output = f32;
        #[inline(always)]
        fn run<L: Level>(self) -> f32 {
            let mut sum = 0.0;
            for ray in self.1 {
                let mut hit = Hit::none(ray);
                self.0.intersect(ray, 0, &mut hit);
                sum += hit.t;
            }
            sum
        }
    }
    // SAFETY: the default level is one this CPU runs (`Isa::default_level`).
    unsafe { Isa::default_level().run(Task(kernel, rays)) }
}

/// Run the packet kernel over all packets once; returns a checksum. The
/// kernel runs on the instruction set of [`Isa::default_level`], as BVH
/// queries do (the packets are converted to its lane type one by one).
#[inline(never)]
pub fn run_packet<K: Intersect, F: SimdFloat>(kernel: &K, packets: &[RayPacket<F>]) -> f32 {
    struct Task<'a, K, F: SimdFloat>(&'a K, &'a [RayPacket<F>]);
    impl<K: Intersect, F: SimdFloat> LevelTask for Task<'_, K, F> {
        type Output = f32;
        #[inline(always)]
        fn run<L: Level>(self) -> f32 {
            match F::LANES {
                4 => packet_loop::<K, F, L::F4>(self.0, self.1),
                8 => packet_loop::<K, F, L::F8>(self.0, self.1),
                16 => packet_loop::<K, F, L::F16>(self.0, self.1),
                _ => packet_loop::<K, F, F>(self.0, self.1),
            }
        }
    }
    // SAFETY: the default level is one this CPU runs (`Isa::default_level`).
    unsafe { Isa::default_level().run(Task(kernel, packets)) }
}

/// The loop of [`run_packet`] with the lanes of `G` (`F`'s width).
#[inline(always)]
fn packet_loop<K: Intersect, F: SimdFloat, G: SimdFloat>(kernel: &K, packets: &[RayPacket<F>]) -> f32 {
    let mut sum = G::splat(0.0);
    for rays in packets {
        let rays = rays.convert::<G>();
        let mut hits = HitPacket::none(&rays);
        kernel.intersect_packet(&rays, 0, &mut hits);
        sum = sum + hits.t;
    }
    let mut total = 0.0;
    for &t in sum.to_array().as_ref() {
        total += t;
    }
    total
}

/// One row of the kernel table: each variant's tests per second, and the
/// packet/scalar ratio from the same rounds.
#[derive(Clone, Debug, serde::Serialize)]
pub struct KernelRow {
    /// Shape name.
    pub primitive: &'static str,
    /// Scalar ray-primitive tests per second.
    pub scalar_per_s: Summary,
    /// 8-wide packet ray-primitive tests per second.
    pub packet8_per_s: Summary,
    /// `packet8_per_s / scalar_per_s`, round by round.
    pub ratio: Summary,
    /// 4-wide packet tests per second (same kernel, `f32x4`).
    pub packet4_per_s: Summary,
    /// 16-wide packet tests per second (same kernel, `f32x16`).
    pub packet16_per_s: Summary,
    /// Rays per measurement.
    pub rays: usize,
    /// Fraction of rays that hit.
    pub hit_rate: f64,
}

impl KernelRow {
    /// The row's figures: each variant's rate and the packet8/scalar ratio.
    pub fn figures(&self) -> Vec<Figure> {
        let labels = |kernel: &str| {
            vec![
                ("primitive", self.primitive.to_string()),
                ("kernel", kernel.to_string()),
            ]
        };
        let mut figures: Vec<Figure> = [
            ("scalar", self.scalar_per_s),
            ("packet8", self.packet8_per_s),
            ("packet4", self.packet4_per_s),
            ("packet16", self.packet16_per_s),
        ]
        .into_iter()
        .map(|(kernel, s)| Figure::new("throughput", "tests/s", Better::Higher, &labels(kernel), s))
        .collect();
        figures.push(Figure::new(
            "packet8/scalar",
            "x",
            Better::Neither,
            &[("primitive", self.primitive.to_string())],
            self.ratio,
        ));
        figures
    }
}

/// The kernel variants, in the order of a round.
pub const VARIANTS: [&str; 4] = ["scalar", "packet8", "packet4", "packet16"];

/// Measures every setup: one sample of each variant per round, interleaved.
pub struct Measure {
    /// Minimum time per timed sample.
    pub sample: Duration,
    /// Samples per variant.
    pub rounds: usize,
    /// The bench timing hooks ([`TimingHooks`]).
    pub hooks: TimingHooks,
    /// The finished rows.
    pub rows: Vec<KernelRow>,
}

impl Measure {
    /// Tests per second of one sample of `f` (each call `per_call` tests) on `variant`.
    fn rate(&self, variant: &str, per_call: usize, mut f: impl FnMut() -> f32) -> f64 {
        let start = Instant::now();
        let mut calls = 0usize;
        // At least one call, so that the rate is positive.
        loop {
            black_box(f());
            calls += 1;
            if start.elapsed() >= self.sample {
                break;
            }
        }
        let tests = (calls * per_call) as f64;
        tests / self.hooks.apply(variant, tests, start.elapsed().as_secs_f64())
    }
}

impl SetupVisitor for Measure {
    fn visit<K: Intersect>(&mut self, setup: &KernelSetup<K>) {
        let (p4, p8, p16) = (
            setup.packets::<f32x4>(),
            setup.packets::<f32x8>(),
            setup.packets::<f32x16>(),
        );
        let n = setup.rays.len();
        let kernel = black_box(&setup.kernel);
        // Warm up, then interleave the variants so drift hits them all alike.
        run_scalar(kernel, &setup.rays);
        let mut samples: [Vec<f64>; 4] = Default::default();
        for _ in 0..self.rounds.max(1) {
            let [scalar, packet8, packet4, packet16] = VARIANTS;
            samples[0].push(self.rate(scalar, n, || run_scalar(kernel, black_box(&setup.rays))));
            samples[1].push(self.rate(packet8, n, || run_packet(kernel, black_box(&p8))));
            samples[2].push(self.rate(packet4, n, || run_packet(kernel, black_box(&p4))));
            samples[3].push(self.rate(packet16, n, || run_packet(kernel, black_box(&p16))));
        }
        // Rates are finite and positive (a sample lasts at least one call).
        let summary = |s: &[f64]| Summary::of(s).expect("finite rates");
        self.rows.push(KernelRow {
            primitive: setup.name,
            scalar_per_s: summary(&samples[0]),
            packet8_per_s: summary(&samples[1]),
            ratio: Summary::paired_ratio(&samples[1], &samples[0]).expect("positive rates"),
            packet4_per_s: summary(&samples[2]),
            packet16_per_s: summary(&samples[3]),
            rays: n,
            hit_rate: setup.hit_rate(),
        });
    }
}
