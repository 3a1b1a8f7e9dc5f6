//! Hit-by-hit agreement of two engines on the same rays.
//!
//! Every ray falls in one class ([`classify`]):
//!
//! | class | meaning |
//! | --- | --- |
//! | both miss | agree |
//! | same primitive | both hit the same primitive with t within `max_ulps` ulps: agree; its t error counts in the quantiles |
//! | t beyond ulps | both hit the same primitive, t more than `max_ulps` ulps apart (still a same-primitive hit in the agreement fractions and the t error quantiles) |
//! | tie | both hit, different primitives, t equal within `tie_tolerance`, and a hit point within `edge_tolerance` of an edge or vertex of either primitive: a ray through an edge or vertex two primitives share; each engine may pick either one |
//! | coincident | both hit, different primitives, t equal within `tie_tolerance`, away from their edges: surfaces that cross or coincide there (or shapes without edges: spheres, planes, cones); either pick is right |
//! | different primitive | both hit, different primitives at different t: a real disagreement |
//! | hit / miss | one engine hits, the other misses: a real disagreement (near silhouettes, usually) |
//!
//! Both the t error and the edge tolerance are relative to the scale of the
//! rounding error of the hit point `p = o + t·d`, the size of its
//! coordinates and of the distance travelled: `max(|p|∞, t·|d|)`. The t error
//! of a ray is the distance between the two hit points, `|t_a − t_b|·|d|`, over
//! that scale; the edge tolerance is `edge_tolerance` times it. Where t·|d| is
//! the larger the t error is the relative `|t_a − t_b| / t_a`; a ray that
//! starts near a surface far from the origin (a secondary ray in a large
//! scene, a ray taken through an instance's transform) meets it at a small t
//! but at coordinates whose rounding no engine avoids, and that rounding, not
//! t, is what two engines can agree to.

use std::borrow::Cow;

use glam::Vec3;

use crate::geometry::Primitive;
use crate::ray::{Hit, Ray};
use crate::scene::Scene;

/// Settings of a comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgreementOptions {
    /// Relative t difference below which two hits on different primitives are a tie.
    pub tie_tolerance: f32,
    /// Distance of a hit point from an edge, relative to its scale (see the
    /// module docs), within which a tie is a shared-edge tie.
    pub edge_tolerance: f32,
    /// Ulps of t beyond which two hits on the same primitive are counted apart.
    pub max_ulps: u32,
    /// How many disagreeing rays to keep for the report.
    pub keep: usize,
}

impl Default for AgreementOptions {
    fn default() -> Self {
        Self {
            tie_tolerance: 1e-4,
            edge_tolerance: 1e-5,
            max_ulps: 16,
            keep: 10,
        }
    }
}

/// The class of a disagreeing ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DisagreementKind {
    /// Engine A hit, engine B missed.
    OnlyA,
    /// Engine B hit, engine A missed.
    OnlyB,
    /// Different primitives at the same t, at an edge or vertex of one of them.
    Tie,
    /// Different primitives at the same t, away from their edges.
    Coincident,
    /// Different primitives at different t.
    DifferentPrimitive,
    /// The same primitive, t more than `max_ulps` ulps apart.
    TBeyondUlps,
}

/// The class of one ray ([`classify`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayClass {
    /// Both engines missed.
    BothMiss,
    /// Both hit the same primitive with t within `max_ulps` ulps.
    SamePrimitive,
    /// Anything else.
    Disagree(DisagreementKind),
}

/// The distance between two finite floats in units in the last place (0 for
/// +0 and −0; the count of representable floats between them otherwise).
pub fn ulps_apart(a: f32, b: f32) -> u32 {
    // Map the bit patterns onto a line: negative floats below the positive ones.
    let ordered = |x: f32| {
        let bits = x.to_bits();
        let magnitude = i64::from(bits & 0x7fff_ffff);
        if bits >> 31 == 1 { -magnitude } else { magnitude }
    };
    // At most 2·(2³¹ − 1), which fits.
    (ordered(a) - ordered(b)).unsigned_abs() as u32
}

/// The edges of a primitive in world space, as segments: a triangle's three, a
/// polygon's outline, a transformed one's mapped through its matrix. Spheres,
/// planes and cones have none (a cone's rims are circles, not counted).
fn edges(prim: &Primitive) -> Vec<(Vec3, Vec3)> {
    let outline = |v: &[Vec3]| (0..v.len()).map(|i| (v[i], v[(i + 1) % v.len()])).collect();
    match prim {
        Primitive::Triangle(t) => outline(&t.vertices()),
        Primitive::Polygon(p) => outline(p.vertices()),
        Primitive::Transformed(t) => {
            let m = t.matrix();
            edges(t.object())
                .into_iter()
                .map(|(a, b)| (m.transform_point3(a), m.transform_point3(b)))
                .collect()
        }
        Primitive::Sphere(_) | Primitive::Plane(_) | Primitive::Cone(_) => Vec::new(),
    }
}

/// Distance from `p` to the segment `[a, b]`.
fn segment_distance(p: Vec3, (a, b): (Vec3, Vec3)) -> f32 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + s * ab)
}

/// Where [`classify`] finds a hit primitive's shape in world space, by id.
pub trait PrimitiveIds {
    /// Primitive `id` in world space; None for an id beyond the last.
    fn world_primitive(&self, id: u32) -> Option<Cow<'_, Primitive>>;
}

/// A flat list, ids its indices.
impl PrimitiveIds for [Primitive] {
    fn world_primitive(&self, id: u32) -> Option<Cow<'_, Primitive>> {
        self.get(id as usize).map(Cow::Borrowed)
    }
}

/// A scene: its own primitives, and its instances' placed one at a time
/// (a scene of 10⁹ instanced primitives is never flattened).
impl PrimitiveIds for Scene {
    fn world_primitive(&self, id: u32) -> Option<Cow<'_, Primitive>> {
        (u64::from(id) < self.id_count()).then(|| Scene::world_primitive(self, id))
    }
}

/// The scale of the rounding error of `ray`'s point at `t`: `max(|p|∞, t·|d|)`.
#[inline]
fn hit_scale(ray: &Ray, t: f32) -> f32 {
    ray.at(t).abs().max_element().max(t.abs() * ray.dir.length())
}

/// The t error of two hits of `ray` at `a` and `b`: the distance between the
/// hit points over the scale of the first's rounding error (module docs).
pub fn t_error(ray: &Ray, a: f32, b: f32) -> f64 {
    let distance = f64::from((a - b).abs()) * f64::from(ray.dir.length());
    distance / f64::from(hit_scale(ray, a).max(f32::MIN_POSITIVE))
}

/// The class of `ray` from the two engines' hits `a` and `b` on `prims`.
pub fn classify<P: PrimitiveIds + ?Sized>(
    prims: &P,
    ray: &Ray,
    a: &Hit,
    b: &Hit,
    options: &AgreementOptions,
) -> RayClass {
    use DisagreementKind::*;
    let kind = match (a.is_hit(), b.is_hit()) {
        (false, false) => return RayClass::BothMiss,
        (true, false) => OnlyA,
        (false, true) => OnlyB,
        (true, true) if a.prim == b.prim => {
            if ulps_apart(a.t, b.t) <= options.max_ulps {
                return RayClass::SamePrimitive;
            }
            TBeyondUlps
        }
        (true, true) if (a.t - b.t).abs() <= options.tie_tolerance * a.t.abs() => {
            // Step 1: the same t; step 2: is either hit point at an edge of
            // either primitive? (Each placed once: an instanced one is copied.)
            let edges: Vec<_> = [a.prim, b.prim]
                .iter()
                .filter_map(|&i| prims.world_primitive(i))
                .flat_map(|prim| edges(&prim))
                .collect();
            let at_edge = [a.t, b.t].iter().any(|&t| {
                let p = ray.at(t);
                let tolerance = options.edge_tolerance * hit_scale(ray, t);
                edges.iter().any(|&e| segment_distance(p, e) <= tolerance)
            });
            if at_edge { Tie } else { Coincident }
        }
        (true, true) => DifferentPrimitive,
    };
    RayClass::Disagree(kind)
}

/// The class of every ray (see [`classify`]).
pub fn classify_rays<P: PrimitiveIds + ?Sized>(
    prims: &P,
    rays: &[Ray],
    a: &[Hit],
    b: &[Hit],
    options: &AgreementOptions,
) -> Vec<RayClass> {
    assert!(a.len() == rays.len() && b.len() == rays.len(), "one hit per ray");
    rays.iter()
        .zip(a.iter().zip(b))
        .map(|(ray, (ha, hb))| classify(prims, ray, ha, hb, options))
        .collect()
}

/// One ray on which the engines disagree, with enough to trace it again.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Disagreement {
    /// Index of the ray in the set.
    pub index: usize,
    /// The class.
    pub kind: DisagreementKind,
    /// Ray origin.
    pub origin: [f32; 3],
    /// Ray direction.
    pub dir: [f32; 3],
    /// Ray interval `[t_min, t_max]`.
    pub interval: [f32; 2],
    /// Engine A's `(t, prim)` (`prim` −1 for a miss).
    pub a: (f32, i64),
    /// Engine B's `(t, prim)`.
    pub b: (f32, i64),
}

/// p50, p99 and maximum of a sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Quantiles {
    /// Median.
    #[serde(deserialize_with = "number_or_nan")]
    pub p50: f64,
    /// 99th percentile.
    #[serde(deserialize_with = "number_or_nan")]
    pub p99: f64,
    /// Maximum.
    #[serde(deserialize_with = "number_or_nan")]
    pub max: f64,
}

/// A number, or NaN where JSON holds `null`: what serde_json writes for NaN
/// and the infinities, so that a result reads back what it wrote.
fn number_or_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(<Option<f64> as serde::Deserialize>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl Quantiles {
    /// Nearest-rank quantiles of `values` (all zero for an empty sample).
    pub fn of(mut values: Vec<f64>) -> Self {
        if values.is_empty() {
            return Self::default();
        }
        values.sort_by(f64::total_cmp);
        let rank = |q: f64| values[((q * values.len() as f64).ceil() as usize).clamp(1, values.len()) - 1];
        Self {
            p50: rank(0.5),
            p99: rank(0.99),
            max: values[values.len() - 1],
        }
    }
}

/// How two engines' hits on the same rays compare.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Agreement {
    /// Rays compared.
    pub rays: usize,
    /// Both missed.
    pub both_miss: usize,
    /// Both hit the same primitive.
    pub same_primitive: usize,
    /// Both hit, different primitives at the same t, at a shared edge or vertex.
    pub ties: usize,
    /// Both hit, different primitives at the same t, away from their edges.
    pub coincident: usize,
    /// Both hit, different primitives at different t.
    pub different_primitive: usize,
    /// A hit, B missed.
    pub only_a: usize,
    /// B hit, A missed.
    pub only_b: usize,
    /// Same-primitive hits (counted in `same_primitive`) with t more than `max_ulps` apart.
    pub t_beyond_ulps: usize,
    /// Relative t error over the same-primitive hits.
    pub t_error: Quantiles,
    /// The first disagreeing rays (ties and t beyond ulps included), in ray order.
    pub disagreements: Vec<Disagreement>,
}

fn record(hit: &Hit) -> (f32, i64) {
    if hit.is_hit() {
        (hit.t, hit.prim as i64)
    } else {
        (f32::INFINITY, -1)
    }
}

impl Agreement {
    /// Compare hits `a` and `b` of the same `rays` on `prims`.
    pub fn compare(
        prims: &[Primitive],
        rays: &[Ray],
        a: &[Hit],
        b: &[Hit],
        options: AgreementOptions,
    ) -> Self {
        let classes = classify_rays(prims, rays, a, b, &options);
        Self::from_classes(rays, a, b, &classes, options.keep)
    }

    /// The counts of rays already classified ([`classify_rays`]), keeping the
    /// first `keep` disagreements.
    pub fn from_classes(rays: &[Ray], a: &[Hit], b: &[Hit], classes: &[RayClass], keep: usize) -> Self {
        assert!(
            a.len() == rays.len() && b.len() == rays.len() && classes.len() == rays.len(),
            "one hit and one class per ray"
        );
        let mut out = Self {
            rays: rays.len(),
            ..Self::default()
        };
        let mut errors = Vec::new();
        for (index, (((ray, ha), hb), class)) in rays.iter().zip(a).zip(b).zip(classes).enumerate() {
            let kind = match *class {
                RayClass::BothMiss => {
                    out.both_miss += 1;
                    continue;
                }
                RayClass::SamePrimitive => {
                    out.same_primitive += 1;
                    errors.push(t_error(ray, ha.t, hb.t));
                    continue;
                }
                RayClass::Disagree(kind) => {
                    match kind {
                        DisagreementKind::TBeyondUlps => {
                            out.same_primitive += 1;
                            out.t_beyond_ulps += 1;
                            errors.push(t_error(ray, ha.t, hb.t));
                        }
                        DisagreementKind::OnlyA => out.only_a += 1,
                        DisagreementKind::OnlyB => out.only_b += 1,
                        DisagreementKind::Tie => out.ties += 1,
                        DisagreementKind::Coincident => out.coincident += 1,
                        DisagreementKind::DifferentPrimitive => out.different_primitive += 1,
                    }
                    kind
                }
            };
            if out.disagreements.len() < keep {
                out.disagreements.push(Disagreement {
                    index,
                    kind,
                    origin: ray.origin.to_array(),
                    dir: ray.dir.to_array(),
                    interval: [ray.t_min, ray.t_max],
                    a: record(ha),
                    b: record(hb),
                });
            }
        }
        out.t_error = Quantiles::of(errors);
        out
    }

    /// Fraction of rays on which both hit or both missed.
    pub fn hit_agreement(&self) -> f64 {
        self.fraction(self.rays - self.only_a - self.only_b)
    }

    /// Fraction of rays with the same result: both missed or hit the same primitive.
    pub fn primitive_agreement(&self) -> f64 {
        self.fraction(self.both_miss + self.same_primitive)
    }

    /// As [`Agreement::primitive_agreement`], counting ties (shared edges) and
    /// coincident surfaces as agreeing.
    pub fn primitive_agreement_with_ties(&self) -> f64 {
        self.fraction(self.both_miss + self.same_primitive + self.ties + self.coincident)
    }

    fn fraction(&self, n: usize) -> f64 {
        if self.rays == 0 {
            1.0
        } else {
            n as f64 / self.rays as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn hit(ray: &Ray, t: f32, prim: u32) -> Hit {
        let mut h = Hit::none(ray);
        h.record(t, prim, 0.0, 0.0);
        h
    }

    #[test]
    fn every_ray_lands_in_one_class() {
        let rays: Vec<Ray> = (0..6)
            .map(|i| Ray::unbounded(Vec3::new(i as f32, 0.0, 0.0), Vec3::Z))
            .collect();
        let miss = |r: &Ray| Hit::none(r);
        let a = vec![
            miss(&rays[0]),
            hit(&rays[1], 2.0, 3),
            hit(&rays[2], 2.0, 3),
            hit(&rays[3], 2.0, 3),
            hit(&rays[4], 2.0, 3),
            miss(&rays[5]),
        ];
        let b = vec![
            miss(&rays[0]),
            hit(&rays[1], 2.0 * (1.0 + 1e-6), 3),
            hit(&rays[2], 2.0, 4),
            hit(&rays[3], 3.0, 4),
            miss(&rays[4]),
            hit(&rays[5], 1.0, 0),
        ];
        let g = Agreement::compare(
            &[],
            &rays,
            &a,
            &b,
            AgreementOptions {
                keep: 3,
                ..Default::default()
            },
        );
        assert_eq!(
            (
                g.both_miss,
                g.same_primitive,
                g.coincident,
                g.different_primitive,
                g.only_a,
                g.only_b
            ),
            (1, 1, 1, 1, 1, 1)
        );
        assert_eq!(g.hit_agreement(), 4.0 / 6.0);
        assert_eq!(g.primitive_agreement(), 2.0 / 6.0);
        assert_eq!(g.primitive_agreement_with_ties(), 3.0 / 6.0);
        assert!((g.t_error.max - 1e-6).abs() < 1e-7);
        let kinds: Vec<_> = g.disagreements.iter().map(|d| (d.index, d.kind)).collect();
        assert_eq!(
            kinds,
            vec![
                (2, DisagreementKind::Coincident),
                (3, DisagreementKind::DifferentPrimitive),
                (4, DisagreementKind::OnlyA)
            ]
        );
        assert_eq!(g.disagreements[2].b, (f32::INFINITY, -1));
        assert_eq!(g.disagreements[0].origin, [2.0, 0.0, 0.0]);
    }

    #[test]
    fn quantiles_use_nearest_rank() {
        let q = Quantiles::of((1..=200).map(f64::from).collect());
        assert_eq!((q.p50, q.p99, q.max), (100.0, 198.0, 200.0));
        assert_eq!(Quantiles::of(vec![]), Quantiles::default());
        assert_eq!(Quantiles::of(vec![5.0]).p99, 5.0);
    }

    /// Two triangles sharing the edge x = 0, y ∈ [−1, 1] in the plane z = 0.
    fn two_triangles() -> Vec<Primitive> {
        use crate::geometry::Triangle;
        vec![
            Primitive::Triangle(Triangle::new(
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(0.0, -1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            )),
            Primitive::Triangle(Triangle::new(
                Vec3::new(0.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            )),
        ]
    }

    /// The class of a ray straight down at `(x, y)` from z = 5, with hits
    /// `(t, prim)` (None: a miss).
    fn class_at(
        prims: &[Primitive],
        x: f32,
        y: f32,
        a: Option<(f32, u32)>,
        b: Option<(f32, u32)>,
    ) -> RayClass {
        let ray = Ray::unbounded(Vec3::new(x, y, 5.0), Vec3::NEG_Z);
        let record = |h: Option<(f32, u32)>| h.map_or(Hit::none(&ray), |(t, p)| hit(&ray, t, p));
        classify(prims, &ray, &record(a), &record(b), &AgreementOptions::default())
    }

    #[test]
    fn the_classifier_on_hand_made_pairs() {
        use DisagreementKind::*;
        let prims = two_triangles();
        let class = |x, y, a, b| class_at(&prims, x, y, a, b);
        let d = RayClass::Disagree;
        // On the shared edge, and at a shared vertex: a tie.
        assert_eq!(class(0.0, 0.3, Some((5.0, 0)), Some((5.0, 1))), d(Tie));
        assert_eq!(class(0.0, 1.0, Some((5.0, 1)), Some((5.0, 0))), d(Tie));
        // Within the edge tolerance (1e-5 of the scale 5), and just beyond it.
        assert_eq!(class(2e-5, 0.3, Some((5.0, 0)), Some((5.0, 1))), d(Tie));
        assert_eq!(class(1e-4, 0.3, Some((5.0, 0)), Some((5.0, 1))), d(Coincident));
        // Equal t inside a triangle, far from every edge: coincident surfaces.
        assert_eq!(class(-0.5, -0.5, Some((5.0, 0)), Some((5.0, 1))), d(Coincident));
        // Different t: a real disagreement, even at the edge.
        assert_eq!(
            class(0.0, 0.3, Some((5.0, 0)), Some((7.0, 1))),
            d(DifferentPrimitive)
        );
        // Hit/miss flips, both ways.
        assert_eq!(class(0.0, 0.3, Some((5.0, 0)), None), d(OnlyA));
        assert_eq!(class(0.0, 0.3, None, Some((5.0, 0))), d(OnlyB));
        assert_eq!(class(0.0, 0.3, None, None), RayClass::BothMiss);
        // The same primitive: within 16 ulps agrees, beyond does not.
        let ulps = |n: u32| f32::from_bits(5f32.to_bits() + n);
        assert_eq!(
            class(0.5, 0.0, Some((5.0, 1)), Some((ulps(16), 1))),
            RayClass::SamePrimitive
        );
        assert_eq!(
            class(0.5, 0.0, Some((5.0, 1)), Some((ulps(17), 1))),
            d(TBeyondUlps)
        );
        // A primitive index out of range has no edges (no panic).
        assert_eq!(class(0.0, 0.3, Some((5.0, 7)), Some((5.0, 9))), d(Coincident));
    }

    #[test]
    fn transformed_edges_are_in_world_space() {
        use crate::geometry::Transformed;
        let moved: Vec<Primitive> = two_triangles()
            .into_iter()
            .map(|p| {
                let t = Transformed::new(p, glam::Mat4::from_translation(Vec3::new(10.0, 0.0, 0.0))).unwrap();
                Primitive::Transformed(Box::new(t))
            })
            .collect();
        let both = (Some((5.0, 0)), Some((5.0, 1)));
        assert_eq!(
            class_at(&moved, 10.0, 0.3, both.0, both.1),
            RayClass::Disagree(DisagreementKind::Tie)
        );
        assert_eq!(
            class_at(&moved, 0.0, 0.3, both.0, both.1),
            RayClass::Disagree(DisagreementKind::Coincident)
        );
    }

    #[test]
    fn the_t_error_is_the_hit_points_distance_over_their_scale() {
        // Far along a ray from near the origin: the relative t difference.
        let from_origin = Ray::unbounded(Vec3::ZERO, Vec3::X);
        assert!((t_error(&from_origin, 100.0, 100.001) - 1e-5).abs() < 1e-7);
        // A ray leaving a surface at x = 1000: one ulp of the hit point's
        // coordinates (6.1e-5) at t = 1e-4 is 61% of t, but 6.1e-8 of its scale.
        let near_surface = Ray::unbounded(Vec3::new(1000.0, 0.0, 0.0), Vec3::Y);
        let ulp = 1000f32.next_up() - 1000.0;
        let e = t_error(&near_surface, 1e-4, 1e-4 + ulp);
        assert!((e - f64::from(ulp) / 1000.0).abs() < 1e-10, "{e}");
        // The direction's length counts: t is in units of |d|.
        let long = Ray::unbounded(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0));
        assert!((t_error(&long, 100.0, 100.001) - 1e-5).abs() < 1e-7);
    }

    #[test]
    fn ulps_count_representable_floats() {
        assert_eq!(ulps_apart(1.0, 1.0), 0);
        assert_eq!(ulps_apart(0.0, -0.0), 0);
        assert_eq!(ulps_apart(1.0, f32::from_bits(1f32.to_bits() + 3)), 3);
        let tiny = f32::from_bits(1);
        assert_eq!(ulps_apart(tiny, -tiny), 2);
        assert_eq!(ulps_apart(f32::MAX, -f32::MAX), 2 * 0x7f7f_ffff);
    }

    #[test]
    fn counts_and_kept_disagreements_follow_the_classes() {
        let prims = two_triangles();
        let rays: Vec<Ray> = [(0.0, 0.3), (0.5, 0.0), (-0.5, -0.5)]
            .iter()
            .map(|&(x, y)| Ray::unbounded(Vec3::new(x, y, 5.0), Vec3::NEG_Z))
            .collect();
        let a = vec![
            hit(&rays[0], 5.0, 0),
            hit(&rays[1], 5.0, 1),
            hit(&rays[2], 5.0, 0),
        ];
        let b = vec![
            hit(&rays[0], 5.0, 1),
            hit(&rays[1], 5.001, 1),
            hit(&rays[2], 5.0, 0),
        ];
        let g = Agreement::compare(&prims, &rays, &a, &b, AgreementOptions::default());
        assert_eq!((g.ties, g.same_primitive, g.t_beyond_ulps), (1, 2, 1));
        let kinds: Vec<_> = g.disagreements.iter().map(|d| d.kind).collect();
        assert_eq!(kinds, [DisagreementKind::Tie, DisagreementKind::TBeyondUlps]);
        assert_eq!(g.primitive_agreement_with_ties(), 1.0);
    }
}
