//! A scene's surfaces as a plain list of triangles, for the engines that take
//! nothing else (the peers), each triangle with the scene primitive it came
//! from, so that their hits name the same primitives as raypack's.

use std::collections::BTreeMap;

use glam::Vec3;

use crate::geometry::Primitive;
use crate::plural;

/// Triangles and the scene primitive each came from (16 + 36 bytes a triangle
/// before an engine copies them into its own layout).
#[derive(Clone, Debug, Default)]
pub struct TriangleSoup {
    /// Each triangle's vertices.
    pub triangles: Vec<[Vec3; 3]>,
    /// Each triangle's primitive index in the scene.
    pub prims: Vec<u32>,
}

impl TriangleSoup {
    /// The triangles of `prims` for `engine`: triangles as they are (degenerate
    /// ones dropped: no ray hits them), polygons ear-clipped on their plane
    /// (as Embree gets them). Any other kind is an error that names what
    /// `engine` cannot take, with its count.
    pub fn new(engine: &str, prims: &[Primitive]) -> anyhow::Result<Self> {
        let mut soup = Self::default();
        let mut refused: BTreeMap<String, u64> = BTreeMap::new();
        for (i, prim) in prims.iter().enumerate() {
            let index = u32::try_from(i)?;
            match prim {
                Primitive::Triangle(t) if t.is_degenerate() => {}
                Primitive::Triangle(t) => soup.push(t.vertices(), index),
                Primitive::Polygon(p) => {
                    let triangles = p.triangles().map_err(|e| {
                        anyhow::anyhow!("{engine}: polygon {i} cannot be split into triangles: {e}")
                    })?;
                    for t in triangles {
                        soup.push(t, index);
                    }
                }
                other => {
                    *refused
                        .entry(format!("{:?}", other.kind()).to_lowercase())
                        .or_default() += 1
                }
            }
        }
        if !refused.is_empty() {
            let kinds: Vec<String> = refused
                .iter()
                .map(|(kind, &n)| plural::count(n, kind, &format!("{kind}s")))
                .collect();
            anyhow::bail!(
                "n/a: {engine} takes triangles (and polygons, split into triangles) only; the scene also has {}",
                kinds.join(", ")
            );
        }
        Ok(soup)
    }

    /// Add triangle `vertices` of primitive `prim`.
    fn push(&mut self, vertices: [Vec3; 3], prim: u32) {
        self.triangles.push(vertices);
        self.prims.push(prim);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Polygon, Sphere, Triangle};

    #[test]
    fn polygons_split_and_other_kinds_are_named() {
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
        let prims = [
            Primitive::Triangle(Triangle::new(a, b, c)),
            Primitive::Triangle(Triangle::new(a, a, c)),
            Primitive::Polygon(Polygon::new(&[a, b, c, d]).unwrap()),
        ];
        let soup = TriangleSoup::new("peer", &prims).unwrap();
        assert_eq!(
            soup.prims,
            [0, 2, 2],
            "the degenerate triangle is dropped, the square split"
        );
        let mut with_spheres = prims.to_vec();
        with_spheres.push(Primitive::Sphere(Sphere::new(Vec3::ZERO, 1.0)));
        with_spheres.push(Primitive::Sphere(Sphere::new(Vec3::ONE, 1.0)));
        let e = TriangleSoup::new("peer", &with_spheres).unwrap_err().to_string();
        assert!(
            e.contains("n/a: peer takes triangles") && e.contains("2 spheres"),
            "{e}"
        );
    }
}
