//! Hit-by-hit agreement of two engines on the same rays.
//!
//! Every ray falls in one class:
//!
//! | class | meaning |
//! | --- | --- |
//! | both miss | agree |
//! | same primitive | both hit the same primitive; its relative t error counts in the quantiles |
//! | tie | both hit, different primitives, t equal within the tolerance: a ray through an edge or vertex shared by two primitives, or through a point where two surfaces cross or coincide; each engine may pick either one |
//! | different primitive | both hit, different primitives at different t: a real disagreement |
//! | hit / miss | one engine hits, the other misses: a real disagreement (near silhouettes, usually) |
//!
//! The relative t error of a ray is `|t_a − t_b| / |t_a|`.

use crate::ray::{Hit, Ray};

/// Settings of a comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgreementOptions {
    /// Relative t difference below which two hits on different primitives are a tie.
    pub tie_tolerance: f32,
    /// How many disagreeing rays to keep for the report.
    pub keep: usize,
}

impl Default for AgreementOptions {
    fn default() -> Self {
        Self {
            tie_tolerance: 1e-4,
            keep: 10,
        }
    }
}

/// The class of a disagreeing ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DisagreementKind {
    /// Engine A hit, engine B missed.
    OnlyA,
    /// Engine B hit, engine A missed.
    OnlyB,
    /// Different primitives at the same t (shared edge or vertex).
    Tie,
    /// Different primitives at different t.
    DifferentPrimitive,
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
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Quantiles {
    /// Median.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Maximum.
    pub max: f64,
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
    /// Both hit, different primitives at the same t.
    pub ties: usize,
    /// Both hit, different primitives at different t.
    pub different_primitive: usize,
    /// A hit, B missed.
    pub only_a: usize,
    /// B hit, A missed.
    pub only_b: usize,
    /// Relative t error over the same-primitive hits.
    pub t_error: Quantiles,
    /// The first disagreeing rays (ties included), in ray order.
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
    /// Compare hits `a` and `b` of the same `rays`.
    pub fn compare(rays: &[Ray], a: &[Hit], b: &[Hit], options: AgreementOptions) -> Self {
        assert!(a.len() == rays.len() && b.len() == rays.len(), "one hit per ray");
        let mut out = Self {
            rays: rays.len(),
            ..Self::default()
        };
        let mut errors = Vec::new();
        for (index, ((ray, ha), hb)) in rays.iter().zip(a).zip(b).enumerate() {
            let kind = match (ha.is_hit(), hb.is_hit()) {
                (false, false) => {
                    out.both_miss += 1;
                    continue;
                }
                (true, true) if ha.prim == hb.prim => {
                    out.same_primitive += 1;
                    errors.push(((ha.t - hb.t).abs() / ha.t.abs()) as f64);
                    continue;
                }
                (true, true) if (ha.t - hb.t).abs() <= options.tie_tolerance * ha.t.abs() => {
                    out.ties += 1;
                    DisagreementKind::Tie
                }
                (true, true) => {
                    out.different_primitive += 1;
                    DisagreementKind::DifferentPrimitive
                }
                (true, false) => {
                    out.only_a += 1;
                    DisagreementKind::OnlyA
                }
                (false, true) => {
                    out.only_b += 1;
                    DisagreementKind::OnlyB
                }
            };
            if out.disagreements.len() < options.keep {
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

    /// As [`Agreement::primitive_agreement`], counting ties (shared edges) as agreeing.
    pub fn primitive_agreement_with_ties(&self) -> f64 {
        self.fraction(self.both_miss + self.same_primitive + self.ties)
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
                g.ties,
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
                (2, DisagreementKind::Tie),
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
}
