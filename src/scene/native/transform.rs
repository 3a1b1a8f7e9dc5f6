//! An object's or include's `transform` table as a matrix, and what it does to
//! what it places: spheres, cones and planes become
//! [`Transformed`](crate::geometry::Transformed) primitives, while vertices and
//! shading normals are baked.

use glam::{Mat3, Mat4, Quat, Vec3, Vec4};

use crate::geometry::{GeometryError, Primitive};
use crate::scene::error::geometry_message;
use crate::scene::instance::placed_primitive;
use crate::scene::native::schema::TransformToml;

/// The matrix of a `transform` table, checked to be affine and invertible.
pub(super) fn transform_matrix(t: TransformToml) -> Result<Mat4, String> {
    let m = match t {
        TransformToml {
            matrix: Some(rows),
            scale: None,
            rotate: None,
            translate: None,
        } => Mat4::from_cols_array_2d(&rows.map(|row| row.map(|x| x.0))).transpose(),
        TransformToml { matrix: Some(_), .. } => {
            return Err("expected either `matrix` or `scale`/`rotate`/`translate`, found both".into());
        }
        TransformToml {
            scale,
            rotate,
            translate,
            ..
        } => {
            let scale = scale.map_or(Vec3::ONE, |s| s.0);
            let rotation = match rotate {
                Some(r) => {
                    let axis = r
                        .axis
                        .0
                        .try_normalize()
                        .ok_or("expected a non-zero rotation axis, found [0, 0, 0]")?;
                    Quat::from_axis_angle(axis, r.degrees.0.to_radians())
                }
                None => Quat::IDENTITY,
            };
            Mat4::from_scale_rotation_translation(scale, rotation, translate.map_or(Vec3::ZERO, |v| v.0))
        }
    };
    if m.row(3) != Vec4::W {
        return Err(geometry_message(&GeometryError::NotAffine));
    }
    let det = m.determinant();
    if det == 0.0 || !det.is_finite() || !m.inverse().is_finite() {
        return Err(geometry_message(&GeometryError::SingularTransform));
    }
    Ok(m)
}

/// `prim` as it is, or under `transform` (composed with an existing transform).
pub(super) fn placed(prim: Primitive, transform: Option<Mat4>) -> Result<Primitive, GeometryError> {
    match transform {
        Some(m) => placed_primitive(&prim, m),
        None => Ok(prim),
    }
}

/// A vertex under the transform.
pub(super) fn bake_point(p: Vec3, transform: Option<Mat4>) -> Vec3 {
    transform.map_or(p, |m| m.transform_point3(p))
}

/// A shading normal under the transform: by `M⁻ᵀ`, renormalised.
pub(super) fn bake_normal(n: Vec3, transform: Option<Mat4>) -> Vec3 {
    match transform {
        Some(m) => (Mat3::from_mat4(m.inverse()).transpose() * n).normalize_or_zero(),
        None => n.normalize_or_zero(),
    }
}
