//! The TOML file's schema: the tables serde reads a scene file into, before
//! the reader turns them into a [`Scene`](crate::scene::Scene). Numbers are
//! checked to be finite f32 ([`Num`]) and every table refuses unknown keys.

use std::collections::BTreeMap;

use glam::Vec3;
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use toml::Spanned;

/// A finite number that fits an f32 (TOML also allows nan and inf).
#[derive(Clone, Copy, Debug)]
pub(super) struct Num(pub(super) f32);

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let x = f64::deserialize(d)?;
        let f = x as f32;
        if !x.is_finite() {
            return Err(D::Error::custom(format!("expected a finite number, found {x}")));
        }
        if !f.is_finite() {
            return Err(D::Error::custom(format!(
                "expected a number within ±3.4e38, found {x:e}"
            )));
        }
        Ok(Num(f))
    }
}

/// A point, vector or colour as written in the file: `[x, y, z]` of finite numbers.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(from = "[Num; 3]")]
pub(super) struct TomlVec3(pub(super) Vec3);

impl From<[Num; 3]> for TomlVec3 {
    fn from([x, y, z]: [Num; 3]) -> Self {
        TomlVec3(Vec3::new(x.0, y.0, z.0))
    }
}

/// The top-level keys other than `objects`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FileToml {
    pub(super) background: Option<TomlVec3>,
    pub(super) camera: Option<Spanned<CameraToml>>,
    #[serde(default)]
    pub(super) materials: BTreeMap<String, MaterialToml>,
    #[serde(default)]
    pub(super) lights: Vec<LightToml>,
    #[serde(default)]
    pub(super) meshes: BTreeMap<String, MeshToml>,
}

/// A named mesh (`[meshes.NAME]`): a scene file that `instance` objects place.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MeshToml {
    pub(super) path: Spanned<String>,
    pub(super) material: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct InstanceToml {
    pub(super) mesh: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraToml {
    pub(super) eye: TomlVec3,
    pub(super) center: TomlVec3,
    pub(super) up: Option<TomlVec3>,
    pub(super) fovx: Num,
    pub(super) fovy: Num,
    pub(super) width: u32,
    pub(super) height: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialToml {
    pub(super) color: Option<TomlVec3>,
    pub(super) kd: Option<Num>,
    pub(super) ks: Option<Num>,
    pub(super) shine: Option<Num>,
    pub(super) transmittance: Option<Num>,
    pub(super) ior: Option<Num>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LightToml {
    pub(super) position: TomlVec3,
    pub(super) color: Option<TomlVec3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SphereToml {
    pub(super) center: TomlVec3,
    pub(super) radius: Spanned<Num>,
    #[serde(default)]
    pub(super) inside_only: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PlaneToml {
    pub(super) implicit: Option<[Num; 4]>,
    pub(super) point: Option<TomlVec3>,
    pub(super) normal: Option<TomlVec3>,
    pub(super) origin: Option<TomlVec3>,
    pub(super) i: Option<TomlVec3>,
    pub(super) j: Option<TomlVec3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TriangleToml {
    pub(super) vertices: [TomlVec3; 3],
    pub(super) normals: Option<[TomlVec3; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PolygonToml {
    pub(super) vertices: Vec<TomlVec3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ConeToml {
    pub(super) base: TomlVec3,
    pub(super) base_radius: Num,
    pub(super) apex: TomlVec3,
    pub(super) apex_radius: Num,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct IncludeToml {
    pub(super) path: Spanned<String>,
    #[serde(default)]
    pub(super) keep_lights: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TransformToml {
    pub(super) matrix: Option<[[Num; 4]; 4]>,
    pub(super) scale: Option<ScaleToml>,
    pub(super) rotate: Option<RotateToml>,
    pub(super) translate: Option<TomlVec3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RotateToml {
    pub(super) axis: TomlVec3,
    pub(super) degrees: Num,
}

/// `scale = 2` or `scale = [sx, sy, sz]`.
pub(super) struct ScaleToml(pub(super) Vec3);

impl<'de> Deserialize<'de> for ScaleToml {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = ScaleToml;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array of 3 numbers")
            }
            fn visit_f64<E: serde::de::Error>(self, x: f64) -> Result<ScaleToml, E> {
                Num::deserialize(serde::de::value::F64Deserializer::<E>::new(x))
                    .map(|s| ScaleToml(Vec3::splat(s.0)))
            }
            fn visit_i64<E: serde::de::Error>(self, x: i64) -> Result<ScaleToml, E> {
                self.visit_f64(x as f64)
            }
            fn visit_u64<E: serde::de::Error>(self, x: u64) -> Result<ScaleToml, E> {
                self.visit_f64(x as f64)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<ScaleToml, A::Error> {
                TomlVec3::deserialize(serde::de::value::SeqAccessDeserializer::new(seq))
                    .map(|v| ScaleToml(v.0))
            }
        }
        d.deserialize_any(Visitor)
    }
}
