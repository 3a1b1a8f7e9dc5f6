//! The picture of a comparison: the scene's primary rays ray-cast in grey
//! (engine A's hits, [`shade::cast`]), each disagreeing pixel painted in the
//! colour of its class, and a caption whose legend names the colours with
//! their counts.

use glam::Vec3;
use image::{Rgb, RgbImage};

use crate::camera::Camera;
use crate::compare::agreement::{DisagreementKind, RayClass};
use crate::compare::ray_sets::primary_rays;
use crate::picture::annotate::annotate;
use crate::ray::Hit;
use crate::render::shade;
use crate::scene::Scene;

/// The classes in legend order, with their colour and its name.
pub const LEGEND: [(DisagreementKind, [u8; 3], &str); 6] = [
    (DisagreementKind::OnlyA, [230, 30, 30], "red"),
    (DisagreementKind::OnlyB, [255, 120, 160], "pink"),
    (DisagreementKind::DifferentPrimitive, [220, 40, 220], "magenta"),
    (DisagreementKind::TBeyondUlps, [255, 160, 0], "orange"),
    (DisagreementKind::Tie, [40, 110, 255], "blue"),
    (DisagreementKind::Coincident, [0, 210, 210], "cyan"),
];

/// The colour of a class.
pub fn colour(kind: DisagreementKind) -> Rgb<u8> {
    let (_, rgb, _) = LEGEND
        .iter()
        .find(|(k, _, _)| *k == kind)
        .copied()
        .unwrap_or(LEGEND[0]);
    Rgb(rgb)
}

/// How the classes are called in the legend; `a` and `b` name the engines and
/// `max_ulps` the ulps bar.
pub fn class_name(kind: DisagreementKind, a: &str, b: &str, max_ulps: u32) -> String {
    match kind {
        DisagreementKind::OnlyA => format!("hit only by {a}"),
        DisagreementKind::OnlyB => format!("hit only by {b}"),
        DisagreementKind::DifferentPrimitive => "different primitive".into(),
        DisagreementKind::TBeyondUlps => format!("same primitive, t > {max_ulps} ulps apart"),
        DisagreementKind::Tie => "tie at a shared edge/vertex".into(),
        DisagreementKind::Coincident => "coincident surfaces".into(),
    }
}

/// The diff image of `camera`'s primary rays ([`primary_rays`]: row order),
/// with A's `hits` and their `classes`, captioned with `caption` and then the legend
/// (the classes named after the `engines` A and B and the `max_ulps` bar).
///
/// # Panics
/// If `hits` and `classes` do not hold one entry per pixel.
pub fn diff_image(
    scene: &Scene,
    camera: &Camera,
    hits: &[Hit],
    classes: &[RayClass],
    mut caption: Vec<String>,
    engines: (&str, &str),
    max_ulps: u32,
) -> RgbImage {
    let (width, height) = (camera.width, camera.height);
    let rays = primary_rays(camera);
    assert!(
        hits.len() == rays.len() && classes.len() == rays.len(),
        "one hit and one class per pixel"
    );
    let mut counts = [0usize; LEGEND.len()];
    let img = RgbImage::from_fn(width, height, |x, y| {
        let i = y as usize * width as usize + x as usize;
        if let RayClass::Disagree(kind) = classes[i] {
            if let Some(k) = LEGEND.iter().position(|(l, _, _)| *l == kind) {
                counts[k] += 1;
            }
            return colour(kind);
        }
        // Grey, dimmed, so that the classes' colours stand out.
        let c = shade::cast(scene, &rays[i], &hits[i]);
        let grey = 0.6 * c.dot(Vec3::new(0.299, 0.587, 0.114)).clamp(0.0, 1.0);
        let byte = (grey * 255.0).round() as u8;
        Rgb([byte, byte, byte])
    });
    // The legend: one field per class, separated by two spaces (the caption breaks there).
    let legend: Vec<String> = LEGEND
        .iter()
        .zip(counts)
        .map(|((kind, _, name), n)| {
            format!(
                "{name}: {} {n}",
                class_name(*kind, engines.0, engines.1, max_ulps)
            )
        })
        .collect();
    caption.push(legend.join("  "));
    annotate(&img, &caption, None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Primitive, Sphere};
    use crate::scene::generate::test_scenes::scene_of;

    #[test]
    fn disagreeing_pixels_take_their_class_colour() {
        let scene = scene_of(
            "test".into(),
            vec![Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0))],
        );
        let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
        let camera = spec.camera_at(3, 2).unwrap();
        let hits: Vec<Hit> = primary_rays(&camera).iter().map(Hit::none).collect();
        let mut classes = vec![RayClass::BothMiss; 6];
        classes[1] = RayClass::Disagree(DisagreementKind::Tie);
        classes[5] = RayClass::Disagree(DisagreementKind::OnlyA);
        let img = diff_image(
            &scene,
            &camera,
            &hits,
            &classes,
            vec!["scene".into()],
            ("raypack", "embree"),
            16,
        );
        assert_eq!(*img.get_pixel(1, 0), colour(DisagreementKind::Tie));
        assert_eq!(*img.get_pixel(2, 1), colour(DisagreementKind::OnlyA));
        let grey = img.get_pixel(0, 0);
        assert!(grey[0] == grey[1] && grey[1] == grey[2], "{grey:?}");
        // The caption band sits below the render.
        assert!(img.height() > 2 && img.width() >= 3);
        // Every class has its own colour.
        for (i, a) in LEGEND.iter().enumerate() {
            assert!(LEGEND[i + 1..].iter().all(|b| a.1 != b.1 && a.0 != b.0));
        }
    }
}
