//! Ideal mirror reflection, Snell refraction, and Whitted's rule for which
//! secondary rays a surface spawns (T. Whitted, "An Improved Illumination Model
//! for Shaded Display", CACM 23(6), 1980), without Fresnel weighting: the
//! weights are the material's Ks and T as NFF gives them, as in the SPD.

use glam::Vec3;

use crate::scene::Material;

/// The mirror direction of `d` about the unit normal `n`: `r = d − 2⟨d, n⟩·n`.
/// Works for either orientation of `n`; `|r| = |d|`.
#[inline]
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

/// The refraction direction of the unit direction `d` through a surface with
/// unit normal `n` facing the incoming ray (`⟨d, n⟩ ≤ 0`), with `eta = η_i / η_t`
/// (index of the side the ray comes from over the side it enters).
///
/// Snell's law `η_i·sin θ_i = η_t·sin θ_t` in vector form:
/// `t = η·d + (η·cos θ_i − cos θ_t)·n` with `cos θ_i = −⟨d, n⟩` and
/// `cos θ_t = √(1 − η²(1 − cos² θ_i))`. Returns None on total internal
/// reflection (the square root's argument is negative). The result is unit length.
#[inline]
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((eta * d + (eta * cos_i - cos_t) * n).normalize())
}

/// A secondary ray a surface spawns: its direction and the weight its colour is
/// added with. 16 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Secondary {
    /// Unit direction.
    pub dir: Vec3,
    /// Weight of the traced colour in the surface's colour.
    pub weight: f32,
}

/// The secondary rays of one hit under Whitted's rules. 40 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Scatter {
    /// Mirror reflection, when Ks > 0 or the surface transmits.
    pub reflect: Option<Secondary>,
    /// Refraction, when T > 0 and there is no total internal reflection.
    pub refract: Option<Secondary>,
}

/// Whitted's rules for a hit with incoming unit direction `d`, unit normal `n`
/// facing the incoming ray, and whether the ray `enters` the object (hits its
/// front side) or leaves it:
///
/// - Ks > 0 spawns a reflection ray of weight Ks;
/// - T > 0 spawns a refraction ray of weight T, with `η = 1/ior` entering and
///   `η = ior` leaving (the outside is vacuum, index 1), and a reflection ray
///   too, even when Ks = 0 (its weight is then 0): the SPD's test procedure
///   (rules 8 and 9 of its README) has every hit on a transmitter spawn a
///   reflection ray, as a Fresnel surface would. SPD `gears`, whose glass has
///   Ks = 0, is the scene where this matters: without it its secondary rays
///   fall 63% short of the published counts;
/// - on total internal reflection there is no refraction ray; its weight T goes
///   to the reflection ray instead.
///
/// A non-positive or non-finite `ior` is taken as 1 (light passes straight through).
pub fn scatter(d: Vec3, n: Vec3, material: &Material, enters: bool) -> Scatter {
    let mut reflect_weight = material.ks.max(0.0);
    let mut refract = None;
    let refract_weight = material.transmittance.max(0.0);
    if refract_weight > 0.0 {
        let ior = if material.ior > 0.0 && material.ior.is_finite() {
            material.ior
        } else {
            1.0
        };
        let eta = if enters { 1.0 / ior } else { ior };
        match self::refract(d, n, eta) {
            Some(dir) => {
                refract = Some(Secondary {
                    dir,
                    weight: refract_weight,
                })
            }
            None => reflect_weight += refract_weight,
        }
    }
    Scatter {
        reflect: (reflect_weight > 0.0 || refract_weight > 0.0).then(|| Secondary {
            dir: reflect(d, n).normalize(),
            weight: reflect_weight,
        }),
        refract,
    }
}
