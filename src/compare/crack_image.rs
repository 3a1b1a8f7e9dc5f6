//! The crack picture of one mesh under one engine: the mesh seen from an
//! oblique camera, each ray of the oracle's edges-and-vertices category
//! ([`edge_outcomes`](crate::compare::robustness::edge_outcomes)) marked at
//! the point of the surface it was aimed at: grey where it hit there
//! (brighter nearer the eye), red where it leaked. Together the grey marks
//! trace the mesh's vertices and edges and the red ones show its cracks; the
//! caption counts the leaks as the oracle's table does.

use glam::Vec3;
use image::{Rgb, RgbImage};

use crate::camera::{Camera, CameraError};
use crate::compare::robustness::{AimedRay, Outcome};
use crate::picture::annotate::annotate;
use crate::plural::count;

/// Width and height of the picture above its caption, in pixels.
pub const SIZE: u32 = 512;

/// A leak's colour.
pub const LEAK: Rgb<u8> = Rgb([255, 40, 40]);

/// The greys of hits, farthest and nearest: dim enough that red stands out.
const GREY: (f32, f32) = (60.0, 190.0);

/// Where the camera looks from, seen from the mesh: oblique to the axes, so
/// that a cube shows three faces and a torus its hole.
const VIEW: Vec3 = Vec3::new(0.8, 0.5, 0.6);

/// Half the width of a leak's square mark, in pixels.
const LEAK_RADIUS: i64 = 2;

/// The camera that frames `points` (their bounding sphere) from an oblique view,
/// z up, at [`SIZE`] × [`SIZE`].
pub fn camera(points: impl Iterator<Item = Vec3> + Clone) -> Result<Camera, CameraError> {
    let (lo, hi) = points
        .clone()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
    let centre = if lo.x <= hi.x { (lo + hi) / 2.0 } else { Vec3::ZERO };
    let radius = points.map(|p| p.distance(centre)).fold(0.0, f32::max);
    // No points, or one: any positive size frames them.
    let radius = if radius > 0.0 { radius } else { 1.0 };
    let distance = 4.0 * radius;
    // The sphere's half angle is asin(1/4); a tenth more leaves a margin.
    let fov = 1.1 * 2.0 * 0.25f32.asin().to_degrees();
    Camera::new(
        centre + distance * VIEW.normalize(),
        centre,
        Vec3::Z,
        fov,
        fov,
        SIZE,
        SIZE,
    )
}

/// The picture of `rays` (one mesh, one engine), captioned `title` and the
/// counts: grey marks at the points of the hits, far ones first, then red
/// ones at the points of the leaks over them, so no crack is hidden.
pub fn crack_image(rays: &[AimedRay], title: String) -> Result<RgbImage, CameraError> {
    let camera = camera(rays.iter().map(|r| r.at))?;
    let depth = |p: Vec3| (camera.eye - p).dot(camera.w);
    let (near, far) = rays.iter().fold((f32::INFINITY, 0.0f32), |(n, f), r| {
        (n.min(depth(r.at)), f.max(depth(r.at)))
    });
    let mut hits: Vec<&AimedRay> = rays.iter().filter(|r| r.outcome != Outcome::Leak).collect();
    hits.sort_by(|a, b| depth(b.at).total_cmp(&depth(a.at)));
    let mut img = RgbImage::new(SIZE, SIZE);
    for ray in hits {
        let nearness = if far > near {
            (far - depth(ray.at)) / (far - near)
        } else {
            1.0
        };
        let byte = (GREY.0 + nearness * (GREY.1 - GREY.0)).round() as u8;
        mark(&mut img, &camera, ray.at, 0, Rgb([byte; 3]));
    }
    for ray in rays.iter().filter(|r| r.outcome == Outcome::Leak) {
        mark(&mut img, &camera, ray.at, LEAK_RADIUS, LEAK);
    }
    Ok(annotate(&img, &[title, legend(rays)], None))
}

/// Paint the square of half-width `radius` pixels around where `camera`
/// sees `p` (the parts inside the image).
fn mark(img: &mut RgbImage, camera: &Camera, p: Vec3, radius: i64, colour: Rgb<u8>) {
    let Some((x, y)) = camera.project(p) else {
        return;
    };
    let (x, y) = (x.floor() as i64, y.floor() as i64);
    for py in y - radius..=y + radius {
        for px in x - radius..=x + radius {
            if (0..i64::from(img.width())).contains(&px) && (0..i64::from(img.height())).contains(&py) {
                img.put_pixel(px as u32, py as u32, colour);
            }
        }
    }
}

/// The caption's count of the marks: the leaks, from which side, of how many rays.
fn legend(rays: &[AimedRay]) -> String {
    let leaks = |inside: bool| {
        rays.iter()
            .filter(|r| r.outcome == Outcome::Leak && r.from_inside == inside)
            .count()
    };
    let (inside, outside) = (leaks(true), leaks(false));
    let n = |n: usize, one: &str, many: &str| count(n as u64, one, many);
    format!(
        "red: {} ({inside} from inside, {outside} from outside)  grey: {} where aimed \
         (brighter nearer)  rays at every vertex, edge midpoint and a random point of every edge",
        n(inside + outside, "leak", "leaks"),
        n(rays.len() - inside - outside, "hit", "hits")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(at: Vec3, from_inside: bool, outcome: Outcome) -> AimedRay {
        AimedRay {
            at,
            from_inside,
            outcome,
        }
    }

    #[test]
    fn hits_are_grey_and_leaks_red_on_top() {
        let (a, b, c) = (
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        );
        let rays = [
            ray(a, true, Outcome::Right),
            ray(a, false, Outcome::Leak),
            ray(b, true, Outcome::Right),
            ray(b, false, Outcome::Right),
            ray(c, false, Outcome::Right),
            ray(-c, true, Outcome::Leak),
        ];
        let img = crack_image(&rays, "test".into()).unwrap();
        assert_eq!(img.width(), SIZE);
        assert!(img.height() > SIZE, "a caption band below");
        let camera = camera(rays.iter().map(|r| r.at)).unwrap();
        let pixel = |p: Vec3| {
            let (x, y) = camera.project(p).unwrap();
            assert!((0.0..SIZE as f32).contains(&x) && (0.0..SIZE as f32).contains(&y));
            *img.get_pixel(x as u32, y as u32)
        };
        // Red wins where a hit and a leak share the point.
        assert_eq!(pixel(a), LEAK);
        assert_eq!(pixel(-c), LEAK);
        for p in [b, c] {
            let grey = pixel(p);
            assert!(
                grey[0] == grey[1] && grey[1] == grey[2] && grey[0] > 0,
                "{grey:?}"
            );
        }
        // Nearer is brighter: b lies nearer the eye than c, looking down.
        assert!(pixel(b)[0] != pixel(c)[0]);
        let near = |p: Vec3| (camera.eye - p).dot(camera.w);
        assert_eq!(near(b) < near(c), pixel(b)[0] > pixel(c)[0]);
        // Away from the marks, the background.
        assert_eq!(*img.get_pixel(0, 0), Rgb([0, 0, 0]));
        assert!(legend(&rays).starts_with("red: 2 leaks (1 from inside, 1 from outside)  grey: 4 hits"));
    }

    #[test]
    fn the_camera_frames_every_point() {
        let points = [
            Vec3::new(-1.0, -1.0, -1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
        ];
        let camera = camera(points.iter().copied()).unwrap();
        for p in points {
            let (x, y) = camera.project(p).unwrap();
            assert!(
                x > 0.0 && x < SIZE as f32 && y > 0.0 && y < SIZE as f32,
                "{p}: ({x}, {y})"
            );
        }
        assert!(camera.project(Vec3::ZERO).is_some());
        assert!(
            self::camera(std::iter::empty()).is_ok(),
            "nothing to frame is no error"
        );
    }
}
