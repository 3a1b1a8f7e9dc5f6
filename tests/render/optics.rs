//! Reflection and refraction directions against hand-computed cases, total
//! internal reflection, and Whitted's rules for which secondary rays a hit spawns.

use glam::Vec3;
use raypack::render::optics::{reflect, refract, scatter};
use raypack::rng::Rng;
use raypack::scene::Material;

const EPS: f32 = 1e-6;

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < EPS
}

/// A direction at `deg` degrees from the normal (0, 1, 0), travelling down and to +x.
fn incoming(deg: f32) -> Vec3 {
    let a = deg.to_radians();
    Vec3::new(a.sin(), -a.cos(), 0.0)
}

fn material(ks: f32, t: f32, ior: f32) -> Material {
    Material {
        ks,
        transmittance: t,
        ior,
        ..Material::default()
    }
}

#[test]
fn reflection_mirrors_about_the_normal() {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    // 45° onto the floor: (s, −s, 0) → (s, s, 0), whichever way the normal points.
    assert!(close(
        reflect(Vec3::new(s, -s, 0.0), Vec3::Y),
        Vec3::new(s, s, 0.0)
    ));
    assert!(close(
        reflect(Vec3::new(s, -s, 0.0), -Vec3::Y),
        Vec3::new(s, s, 0.0)
    ));
    // Head-on: straight back.
    assert!(close(reflect(-Vec3::Z, Vec3::Z), Vec3::Z));
    // Grazing: a ray along the surface is unchanged.
    assert!(close(reflect(Vec3::X, Vec3::Y), Vec3::X));
    // A tilted normal n = (0, 1, 1)/√2: d = (0, 0, −1) goes to (0, 1, 0).
    assert!(close(
        reflect(-Vec3::Z, Vec3::new(0.0, 1.0, 1.0).normalize()),
        Vec3::Y
    ));
}

#[test]
fn refraction_follows_snells_law_in_hand_computed_cases() {
    // Normal incidence passes straight through at any index.
    for eta in [1.0 / 1.5, 1.5, 1.0] {
        assert!(close(refract(-Vec3::Y, Vec3::Y, eta).unwrap(), -Vec3::Y));
    }
    // Air to glass (η = 1/1.5) at 45°: sin θt = sin 45° / 1.5 = 0.471405,
    // cos θt = √(1 − 0.222222) = 0.881917.
    let t = refract(incoming(45.0), Vec3::Y, 1.0 / 1.5).unwrap();
    assert!(close(t, Vec3::new(0.471_404_5, -0.881_917_1, 0.0)), "{t}");
    // Glass to air at 30°: sin θt = 1.5 · 0.5 = 0.75, cos θt = √(1 − 0.5625) = 0.661438.
    let t = refract(incoming(30.0), Vec3::Y, 1.5).unwrap();
    assert!(close(t, Vec3::new(0.75, -0.661_437_8, 0.0)), "{t}");
    // η = 1 changes nothing.
    assert!(close(
        refract(incoming(70.0), Vec3::Y, 1.0).unwrap(),
        incoming(70.0)
    ));
}

#[test]
fn total_internal_reflection_past_the_critical_angle() {
    // Glass to air: critical angle asin(1/1.5) = 41.81°.
    assert!(refract(incoming(41.0), Vec3::Y, 1.5).is_some());
    assert!(refract(incoming(42.0), Vec3::Y, 1.5).is_none());
    assert!(refract(incoming(45.0), Vec3::Y, 1.5).is_none());
    assert!(refract(incoming(89.9), Vec3::Y, 1.5).is_none());
    // Just below the critical angle the refracted ray almost grazes the surface.
    let t = refract(incoming(41.8), Vec3::Y, 1.5).unwrap();
    assert!(t.x > 0.99 && t.y < 0.0, "{t}");
    // Air to glass never reflects totally, even at grazing incidence.
    let t = refract(incoming(90.0), Vec3::Y, 1.0 / 1.5).unwrap();
    assert!((t.x - 1.0 / 1.5).abs() < 1e-5, "{t}");
}

#[test]
fn random_refractions_obey_snell_and_stay_in_the_plane_of_incidence() {
    let mut rng = Rng::new(11);
    for _ in 0..100_000 {
        let n = rng.unit_vector();
        let mut d = rng.unit_vector();
        if d.dot(n) > 0.0 {
            d = -d;
        }
        let eta = rng.range(0.4, 2.5);
        let sin_i = d.cross(n).length();
        match refract(d, n, eta) {
            Some(t) => {
                assert!((t.length() - 1.0).abs() < 1e-5);
                // Snell: η·sin θi = sin θt, and the ray goes on through the surface.
                assert!((eta * sin_i - t.cross(n).length()).abs() < 1e-4, "{d} {n} {eta}");
                assert!(t.dot(n) <= 1e-6);
                // Coplanar with d and n.
                assert!(t.dot(d.cross(n)).abs() < 1e-4);
            }
            None => assert!(eta * sin_i > 0.9999, "TIR at η·sin θ = {}", eta * sin_i),
        }
    }
}

#[test]
fn whitted_rules_pick_the_secondary_rays() {
    let d = incoming(45.0);
    let n = Vec3::Y;
    // Opaque diffuse: nothing.
    assert_eq!(scatter(d, n, &material(0.0, 0.0, 1.0), true), Default::default());
    // Mirror: reflection of weight Ks only.
    let s = scatter(d, n, &material(0.4, 0.0, 1.0), true);
    assert_eq!(s.reflect.unwrap().weight, 0.4);
    assert!(close(s.reflect.unwrap().dir, reflect(d, n)));
    assert!(s.refract.is_none());
    // Glass hit from outside: refraction with η = 1/ior, reflection with Ks.
    let s = scatter(d, n, &material(0.1, 0.8, 1.5), true);
    assert_eq!(s.refract.unwrap().weight, 0.8);
    assert!(close(s.refract.unwrap().dir, refract(d, n, 1.0 / 1.5).unwrap()));
    assert_eq!(s.reflect.unwrap().weight, 0.1);
    // Leaving glass at 30°: η = ior; a transmitter spawns a reflection ray even
    // with Ks = 0 (the SPD's rule 8), of weight 0.
    let s = scatter(incoming(30.0), n, &material(0.0, 0.8, 1.5), false);
    assert!(close(s.refract.unwrap().dir, Vec3::new(0.75, -0.661_437_8, 0.0)));
    assert_eq!(s.reflect.unwrap().weight, 0.0);
    assert!(close(s.reflect.unwrap().dir, reflect(incoming(30.0), n)));
    // Leaving glass at 45°: total internal reflection, only a reflection ray,
    // carrying the transmitted weight too.
    let s = scatter(d, n, &material(0.1, 0.8, 1.5), false);
    assert!(s.refract.is_none());
    assert!((s.reflect.unwrap().weight - 0.9).abs() < EPS);
    assert!(close(s.reflect.unwrap().dir, reflect(d, n)));
    let s = scatter(d, n, &material(0.0, 0.5, 1.5), false);
    assert_eq!(s.reflect.unwrap().weight, 0.5);
    // A meaningless index of refraction lets light straight through.
    for ior in [0.0, -2.0, f32::NAN, f32::INFINITY] {
        let s = scatter(d, n, &material(0.0, 1.0, ior), true);
        assert!(close(s.refract.unwrap().dir, d), "ior {ior}");
    }
}
