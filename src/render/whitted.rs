//! Recursive ray tracing after Whitted ("An Improved Illumination Model for
//! Shaded Display", CACM 23(6), 1980), the lecture's section 8, on batches of rays.
//!
//! At every hit: Phong shading with one shadow ray per light (none when the
//! shading normal faces away from the light), then the secondary rays of
//! [`optics::scatter`] while the depth limit allows (the eye ray has depth 1).
//! All queries of one level go through the [`TraceKernel`] as batches with lane
//! masks: one shadow batch per light, one reflection batch, one refraction batch,
//! each traced recursively as a whole. The shading itself is scalar per lane and
//! shared by both kernels, so scalar and packet renders spawn the same rays. A
//! secondary or shadow ray stays in its pixel's lane, so a lane's traversal
//! cost is its pixel's whole ray tree.
//!
//! Light: `Σ_lights s·c_l·(Kd·C·⟨n, l⟩ + Ks·⟨r, v⟩^shine)` over unblocked lights,
//! plus an ambient `0.1·Kd·C` so shadows are not pitch black, plus `Ks` times the
//! reflected and `T` times the refracted colour. NFF lights carry no intensity,
//! so each is scaled by `s = 1/√(number of lights)`, which keeps scenes
//! with many lights from saturating.

use glam::Vec3;

use crate::accel::Accel;
use crate::bounds::Aabb;
use crate::ray::Ray;
use crate::render::batch::{BATCH, Hits, Rays};
use crate::render::counting::{Tally, TileCounter};
use crate::render::kernel::TraceKernel;
use crate::render::optics::{self, Secondary};
use crate::render::surface::Surface;
use crate::scene::Scene;

/// Ambient fraction of the diffuse colour.
const AMBIENT: f32 = 0.1;

/// Everything the recursion needs: the scene, its acceleration structure, the
/// secondary-ray epsilon, the depth limit. 24 bytes.
#[derive(Clone, Copy, Debug)]
pub struct Tracer<'a, A> {
    /// The scene (materials, lights, background, vertex normals).
    pub scene: &'a Scene,
    /// Ray queries over `scene.primitives`.
    pub accel: &'a A,
    /// `t_min` of secondary and shadow rays; see [`ray_epsilon`].
    pub epsilon: f32,
    /// Maximum tree depth, the eye ray being depth 1.
    pub max_depth: u32,
}

/// The `t_min` of secondary and shadow rays, which start on a surface: `1e-4`
/// times the scene's scale (the largest coordinate magnitude of the bounded
/// primitives' box and of the eye, or the box's largest extent). A hit point's
/// rounding error grows with its coordinates, about `1e-7·|p|` per operation in
/// f32, so this keeps several hundred ulps between a surface and the start of
/// its secondary rays, while staying far below any feature size of the SPD scenes.
pub fn ray_epsilon(scene: &Scene, eye: Vec3) -> f32 {
    epsilon_for(scene.bounds(), eye)
}

/// [`ray_epsilon`] of a scene whose bounded primitives fill `bounds`, seen from `eye`.
pub fn epsilon_for(bounds: Aabb, eye: Vec3) -> f32 {
    let b = bounds;
    let mut scale = eye.abs().max_element();
    if !b.is_empty() {
        scale = scale
            .max(b.min.abs().max_element())
            .max(b.max.abs().max_element())
            .max(b.extent().max_element());
    }
    if !scale.is_finite() {
        scale = 1.0;
    }
    (1e-4 * scale).max(1e-6)
}

/// Lanes of a mask, lowest first.
#[inline]
pub(crate) fn lanes(mask: u32) -> impl Iterator<Item = usize> {
    (0..BATCH).filter(move |i| mask >> i & 1 == 1)
}

impl<A: Accel> Tracer<'_, A> {
    /// Trace the lanes of `active` at `depth` and return their colours.
    pub fn trace<K: TraceKernel, C: TileCounter>(
        &self,
        rays: &Rays,
        active: u32,
        depth: u32,
        tally: &mut Tally<C>,
    ) -> [Vec3; BATCH] {
        let hits = K::intersect(self.accel, rays, active, &mut tally.traversal);
        self.shade::<K, C>(rays, active, &hits, depth, tally)
    }

    /// Colours of the lanes of `active` whose nearest hits are `hits`: the
    /// background where nothing was hit, Whitted shading elsewhere.
    pub fn shade<K: TraceKernel, C: TileCounter>(
        &self,
        rays: &Rays,
        active: u32,
        hits: &Hits,
        depth: u32,
        tally: &mut Tally<C>,
    ) -> [Vec3; BATCH] {
        let scene = self.scene;
        let mut color = [scene.background; BATCH];
        let hit_mask = lanes(active)
            .filter(|&i| hits[i].is_hit())
            .fold(0u32, |m, i| m | 1 << i);
        let surfaces: [Option<Surface>; BATCH] =
            std::array::from_fn(|i| (hit_mask >> i & 1 == 1).then(|| Surface::at(scene, &rays[i], &hits[i])));
        for i in lanes(hit_mask) {
            let m = surfaces[i].as_ref().expect("hit lane").material;
            color[i] = AMBIENT * m.kd * m.color;
        }
        self.add_direct_light::<K, C>(rays, hit_mask, &surfaces, &mut color, tally);
        if depth < self.max_depth {
            self.add_secondary::<K, C>(rays, hit_mask, &surfaces, depth, &mut color, tally);
        }
        color
    }

    /// Phong terms of every light, each light's shadow rays traced as one batch.
    fn add_direct_light<K: TraceKernel, C: TileCounter>(
        &self,
        rays: &Rays,
        hit_mask: u32,
        surfaces: &[Option<Surface>; BATCH],
        color: &mut [Vec3; BATCH],
        tally: &mut Tally<C>,
    ) {
        let lights = &self.scene.lights;
        if lights.is_empty() || hit_mask == 0 {
            return;
        }
        let scale = 1.0 / (lights.len() as f32).sqrt();
        for light in lights {
            // Step 1: a shadow ray from every lit-side surface point to the light.
            let mut shadow = *rays;
            let mut mask = 0u32;
            for i in lanes(hit_mask) {
                let s = surfaces[i].as_ref().expect("hit lane");
                let to_light = light.position - s.point;
                let distance = to_light.length();
                let l = to_light / distance;
                if distance > self.epsilon && s.normal.dot(l) > 0.0 {
                    shadow[i] = Ray::new(s.point, l, self.epsilon, distance);
                    mask |= 1 << i;
                }
            }
            if mask == 0 {
                continue;
            }
            // Step 2: which of them something blocks.
            let blocked = K::occluded(self.accel, &shadow, mask, &mut tally.traversal);
            tally.rays.shadow_rays += u64::from(mask.count_ones());
            tally.rays.shadow_blocked += u64::from(blocked.count_ones());
            // Step 3: diffuse and specular light where nothing does.
            for i in lanes(mask & !blocked) {
                let s = surfaces[i].as_ref().expect("hit lane");
                let m = s.material;
                let l = shadow[i].dir;
                let mut c = m.kd * s.normal.dot(l) * m.color;
                if m.ks > 0.0 && m.shine > 0.0 {
                    let r = optics::reflect(-l, s.normal);
                    let cos = r.dot(-rays[i].dir).max(0.0);
                    c += Vec3::splat(m.ks * cos.powf(m.shine));
                }
                color[i] += scale * light.color * c;
            }
        }
    }

    /// Reflected and refracted colour: the secondary rays of every lane, traced
    /// one level deeper as two batches.
    fn add_secondary<K: TraceKernel, C: TileCounter>(
        &self,
        rays: &Rays,
        hit_mask: u32,
        surfaces: &[Option<Surface>; BATCH],
        depth: u32,
        color: &mut [Vec3; BATCH],
        tally: &mut Tally<C>,
    ) {
        let mut reflect = Batch::new(rays);
        let mut refract = Batch::new(rays);
        for i in lanes(hit_mask) {
            let s = surfaces[i].as_ref().expect("hit lane");
            let scatter = optics::scatter(rays[i].dir, s.normal, s.material, s.front);
            // Total internal reflection: counted apart, for the SPD's tally.
            if s.material.transmittance > 0.0 && scatter.refract.is_none() {
                tally.rays.total_internal_reflections += 1;
            }
            reflect.set(i, s.point, scatter.reflect, self.epsilon);
            refract.set(i, s.point, scatter.refract, self.epsilon);
        }
        tally.rays.reflect_rays += u64::from(reflect.mask.count_ones());
        tally.rays.refract_rays += u64::from(refract.mask.count_ones());
        for batch in [reflect, refract] {
            if batch.mask == 0 {
                continue;
            }
            let traced = self.trace::<K, C>(&batch.rays, batch.mask, depth + 1, tally);
            for i in lanes(batch.mask) {
                color[i] += batch.weight[i] * traced[i];
            }
        }
    }
}

/// Secondary rays of one kind, one per lane, with their weights. 292 bytes.
struct Batch {
    rays: Rays,
    weight: [f32; BATCH],
    mask: u32,
}

impl Batch {
    /// An empty batch; unused lanes keep copies of `rays` so no lane holds garbage.
    fn new(rays: &Rays) -> Self {
        Self {
            rays: *rays,
            weight: [0.0; BATCH],
            mask: 0,
        }
    }

    /// Put the secondary ray `s` (if any) from `point` in lane `i`.
    fn set(&mut self, i: usize, point: Vec3, s: Option<Secondary>, epsilon: f32) {
        if let Some(s) = s {
            self.rays[i] = Ray::new(point, s.dir, epsilon, f32::INFINITY);
            self.weight[i] = s.weight;
            self.mask |= 1 << i;
        }
    }
}
