//! The pinhole camera of the lecture (section 3).
//!
//! Right-handed basis, the camera looks down −w:
//! `w = (eye − center)/|eye − center|`, `u = (up × w)/|up × w|`, `v = w × u`.
//! The image plane lies at distance 1 and spans `2·tan(fovx/2) × 2·tan(fovy/2)`.
//! Image coordinates `(x, y)` run right and down over `[0, width] × [0, height]`;
//! the centre of pixel `(i, j)` is `(i + 0.5, j + 0.5)`.

use glam::Vec3;

use crate::packet::RayPacket;
use crate::ray::Ray;
use crate::simd::SimdFloat;

/// Why a camera cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CameraError {
    /// `eye` and `center` coincide, so there is no view direction.
    #[error("camera eye and look-at point coincide")]
    NoViewDirection,
    /// `up` is zero or parallel to the view direction.
    #[error("camera up vector is zero or parallel to the view direction")]
    UpParallelToView,
    /// A field of view outside `(0°, 180°)`.
    #[error("field of view {0}° is not in (0°, 180°)")]
    BadFieldOfView(f32),
    /// A zero image dimension.
    #[error("image size {0}x{1} is empty")]
    EmptyImage(u32, u32),
    /// A NaN or infinite input.
    #[error("camera has a non-finite coordinate")]
    NotFinite,
}

/// A camera with its basis precomputed. 64 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Right axis.
    pub u: Vec3,
    /// Up axis of the image.
    pub v: Vec3,
    /// Backward axis (the camera looks down −w).
    pub w: Vec3,
    /// `tan(fovx/2)`.
    pub tan_half_fovx: f32,
    /// `tan(fovy/2)`.
    pub tan_half_fovy: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// Build the lecture's camera; field-of-view angles in degrees.
    pub fn new(
        eye: Vec3,
        center: Vec3,
        up: Vec3,
        fovx_deg: f32,
        fovy_deg: f32,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        if !(eye.is_finite() && center.is_finite() && up.is_finite()) {
            return Err(CameraError::NotFinite);
        }
        for fov in [fovx_deg, fovy_deg] {
            if !(fov > 0.0 && fov < 180.0) {
                return Err(CameraError::BadFieldOfView(fov));
            }
        }
        if width == 0 || height == 0 {
            return Err(CameraError::EmptyImage(width, height));
        }
        let w = (eye - center)
            .try_normalize()
            .ok_or(CameraError::NoViewDirection)?;
        let u = up.cross(w).try_normalize().ok_or(CameraError::UpParallelToView)?;
        let v = w.cross(u);
        Ok(Self {
            eye,
            u,
            v,
            w,
            tan_half_fovx: (fovx_deg.to_radians() * 0.5).tan(),
            tan_half_fovy: (fovy_deg.to_radians() * 0.5).tan(),
            width,
            height,
        })
    }

    /// The primary ray through image point `(x, y)`: it starts on the image plane
    /// at `p = eye + α·u + β·v − w` and points away from the eye.
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let half_w = self.width as f32 * 0.5;
        let half_h = self.height as f32 * 0.5;
        let alpha = self.tan_half_fovx * (x - half_w) / half_w;
        let beta = self.tan_half_fovy * (half_h - y) / half_h;
        let offset = alpha * self.u + beta * self.v - self.w;
        Ray::unbounded(self.eye + offset, offset.normalize())
    }

    /// The image point `(x, y)` that `p` is seen at, the inverse of
    /// [`Camera::ray`] (the ray through it passes through `p`), whether or
    /// not it lies inside the image; `None` for a point not in front of the
    /// eye. Its depth along the view is `(eye − p)·w`.
    pub fn project(&self, p: Vec3) -> Option<(f32, f32)> {
        let d = p - self.eye;
        let depth = -d.dot(self.w);
        (depth > 0.0).then(|| {
            let (alpha, beta) = (d.dot(self.u) / depth, d.dot(self.v) / depth);
            let half_w = self.width as f32 * 0.5;
            let half_h = self.height as f32 * 0.5;
            (
                half_w + alpha / self.tan_half_fovx * half_w,
                half_h - beta / self.tan_half_fovy * half_h,
            )
        })
    }

    /// The primary ray through the centre of pixel `(i, j)`.
    #[inline]
    pub fn pixel_ray(&self, i: u32, j: u32) -> Ray {
        self.ray(i as f32 + 0.5, j as f32 + 0.5)
    }

    /// A packet of primary rays through pixel centres, one pixel per lane; lanes
    /// past `pixels.len()` and pixels outside the image are inactive. Each lane
    /// holds exactly the ray [`Camera::pixel_ray`] makes, so scalar and packet
    /// renders trace the same rays.
    pub fn pixel_packet<F: SimdFloat>(&self, pixels: &[(u32, u32)]) -> RayPacket<F> {
        let mut rays = [Ray::unbounded(self.eye, -self.w); 32];
        let mut mask = 0u32;
        for (lane, &(i, j)) in pixels.iter().enumerate().take(F::LANES) {
            rays[lane] = self.pixel_ray(i, j);
            if i < self.width && j < self.height {
                mask |= 1 << lane;
            }
        }
        RayPacket::from_rays_masked(&rays[..F::LANES], mask)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera::new(
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::ZERO,
            Vec3::Y,
            90.0,
            60.0,
            200,
            100,
        )
        .unwrap()
    }

    #[test]
    fn basis_is_right_handed_and_orthonormal() {
        let c = cam();
        assert!((c.w - Vec3::Z).length() < 1e-6);
        assert!((c.u - Vec3::X).length() < 1e-6);
        assert!((c.v - Vec3::Y).length() < 1e-6);
        assert!((c.u.cross(c.v) - c.w).length() < 1e-6);
    }

    #[test]
    fn centre_ray_looks_at_center_and_corners_span_the_field_of_view() {
        let c = cam();
        let r = c.ray(100.0, 50.0);
        assert!((r.dir - (-Vec3::Z)).length() < 1e-6);
        assert!((r.origin - Vec3::new(0.0, 0.0, 4.0)).length() < 1e-6);
        // The left edge of the image is fovx/2 = 45° off axis, the top edge fovy/2 = 30°.
        let left = c.ray(0.0, 50.0);
        assert!((left.dir.angle_between(-Vec3::Z).to_degrees() - 45.0).abs() < 1e-3);
        assert!(left.dir.x < 0.0);
        let top = c.ray(100.0, 0.0);
        assert!((top.dir.angle_between(-Vec3::Z).to_degrees() - 30.0).abs() < 1e-3);
        assert!(top.dir.y > 0.0);
    }

    #[test]
    fn project_inverts_the_primary_rays() {
        let c = Camera::new(
            Vec3::new(1.0, 2.0, 5.0),
            Vec3::new(0.5, 0.0, -1.0),
            Vec3::Y,
            70.0,
            50.0,
            64,
            48,
        )
        .unwrap();
        for (x, y) in [(0.0, 0.0), (32.0, 24.0), (63.5, 10.25), (5.0, 47.0), (80.0, -3.0)] {
            let ray = c.ray(x, y);
            for t in [0.5, 3.0, 40.0] {
                let (px, py) = c.project(ray.at(t)).expect("in front of the eye");
                assert!(
                    (px - x).abs() < 1e-3 && (py - y).abs() < 1e-3,
                    "({x}, {y}) at t {t}: ({px}, {py})"
                );
            }
        }
        assert_eq!(c.project(c.eye + c.w), None, "behind the eye");
        assert_eq!(c.project(c.eye), None, "at the eye");
    }

    #[test]
    fn packet_lanes_equal_scalar_rays() {
        let c = cam();
        let pixels: Vec<(u32, u32)> = (0..8).map(|k| (k % 4 + 10, k / 4 + 20)).collect();
        let p = c.pixel_packet::<wide::f32x8>(&pixels);
        for (lane, &(i, j)) in pixels.iter().enumerate() {
            assert_eq!(p.ray(lane), c.pixel_ray(i, j));
            assert!(p.is_active(lane));
        }
        let partial = c.pixel_packet::<wide::f32x8>(&pixels[..3]);
        assert_eq!(partial.active.bitmask(), 0b111);
    }

    #[test]
    fn degenerate_cameras_are_errors() {
        let e = Vec3::new(0.0, 0.0, 5.0);
        assert_eq!(
            Camera::new(e, e, Vec3::Y, 60.0, 60.0, 8, 8),
            Err(CameraError::NoViewDirection)
        );
        assert_eq!(
            Camera::new(e, Vec3::ZERO, Vec3::Z, 60.0, 60.0, 8, 8),
            Err(CameraError::UpParallelToView)
        );
        assert!(Camera::new(e, Vec3::ZERO, Vec3::Y, 180.0, 60.0, 8, 8).is_err());
        assert!(Camera::new(e, Vec3::ZERO, Vec3::Y, 60.0, 60.0, 0, 8).is_err());
        assert!(Camera::new(Vec3::NAN, Vec3::ZERO, Vec3::Y, 60.0, 60.0, 8, 8).is_err());
    }
}
