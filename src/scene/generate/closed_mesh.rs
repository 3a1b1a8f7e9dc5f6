//! Closed triangle meshes with shared vertices, whose inside is known by
//! construction: what the robustness oracle aims rays through (their shared
//! edges and vertices) and what watertightness is tested on. Built in f64 in
//! their own frame, then placed (scaled and moved) and rounded to f32 once,
//! so every triangle sharing a vertex reads the same f32 point.

use std::collections::HashMap;

use glam::{DVec3, Vec3};

use crate::geometry::{Primitive, Triangle};

/// The closed meshes of the oracle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ClosedShape {
    /// A subdivided icosahedron on the unit sphere (4 subdivisions: 5,120 triangles).
    Icosphere,
    /// A torus (major radius 1, minor 0.35), 64 × 24 quads as 3,072 triangles.
    Torus,
    /// The cube `[−1, 1]³`, each face a 16 × 16 grid: 3,072 triangles, many
    /// edges on the cube's edges and corners where six or more triangles meet.
    CubeGrid,
    /// A closed cylinder of radius 0.02 and length 2 with 96 sides: long thin
    /// triangles (aspect about 1,500) down its side, fans at its ends.
    ThinCylinder,
    /// A regular tetrahedron, the SPD `tetra`'s element: four faces, every
    /// edge and vertex at a sharp angle.
    Tetrahedron,
}

impl ClosedShape {
    /// Every shape.
    pub const ALL: [ClosedShape; 5] = [
        ClosedShape::Icosphere,
        ClosedShape::Torus,
        ClosedShape::CubeGrid,
        ClosedShape::ThinCylinder,
        ClosedShape::Tetrahedron,
    ];

    /// The name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            ClosedShape::Icosphere => "icosphere",
            ClosedShape::Torus => "torus",
            ClosedShape::CubeGrid => "cube-grid",
            ClosedShape::ThinCylinder => "thin-cylinder",
            ClosedShape::Tetrahedron => "tetrahedron",
        }
    }
}

/// Where a mesh's inside is, in its own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Inside {
    /// A convex mesh: every segment from the centre to its surface stays inside.
    Convex,
    /// A torus of major radius `.0` about z: every segment from the ring
    /// circle to a surface point in the same half-plane through the z axis stays inside.
    Ring(f64),
}

/// A closed mesh placed in the world: f32 vertices and the triangles over them.
#[derive(Clone, Debug)]
pub struct ClosedMesh {
    /// The shape it was made as.
    pub shape: ClosedShape,
    /// Vertices, after placement, rounded to f32 once.
    pub vertices: Vec<Vec3>,
    /// Vertex indices of each triangle, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Where its inside is.
    inside: Inside,
    /// The placement: `world = offset + scale · local`.
    scale: f64,
    /// See `scale`.
    offset: DVec3,
}

/// A mesh in its own frame, in f64.
struct LocalMesh {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl ClosedMesh {
    /// `shape` scaled by `scale` and moved by `offset`.
    pub fn new(shape: ClosedShape, scale: f64, offset: DVec3) -> Self {
        let (local, inside) = match shape {
            ClosedShape::Icosphere => (icosphere(4), Inside::Convex),
            ClosedShape::Torus => (torus(1.0, 0.35, 64, 24), Inside::Ring(1.0)),
            ClosedShape::CubeGrid => (cube_grid(16), Inside::Convex),
            ClosedShape::ThinCylinder => (cylinder(0.02, 1.0, 96), Inside::Convex),
            ClosedShape::Tetrahedron => (tetrahedron(), Inside::Convex),
        };
        Self {
            shape,
            vertices: local
                .vertices
                .iter()
                .map(|&v| (offset + scale * v).as_vec3())
                .collect(),
            triangles: local.triangles,
            inside,
            scale,
            offset,
        }
    }

    /// The triangles as primitives, in order (a hit's primitive index is the
    /// triangle's position here).
    pub fn primitives(&self) -> Vec<Primitive> {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize]);
                Primitive::Triangle(Triangle::new(a, b, c))
            })
            .collect()
    }

    /// Each undirected edge once, with the (one or two) triangles on it.
    pub fn edges(&self) -> Vec<([u32; 2], Vec<u32>)> {
        let mut edges: HashMap<[u32; 2], Vec<u32>> = HashMap::new();
        for (i, t) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.entry([a.min(b), a.max(b)]).or_default().push(i as u32);
            }
        }
        let mut edges: Vec<_> = edges.into_iter().collect();
        edges.sort_unstable_by_key(|(e, _)| *e);
        edges
    }

    /// A point inside the mesh from which the segment to the surface point
    /// `p` (in the world) stays inside, so a ray from it through `p` crosses
    /// the surface there first.
    pub fn inside_towards(&self, p: DVec3) -> DVec3 {
        let local = (p - self.offset) / self.scale;
        let centre = match self.inside {
            Inside::Convex => DVec3::ZERO,
            Inside::Ring(radius) => {
                let around = DVec3::new(local.x, local.y, 0.0);
                radius * around.try_normalize().unwrap_or(DVec3::X)
            }
        };
        self.offset + self.scale * centre
    }

    /// The size of the mesh in the world: its scale.
    pub fn size(&self) -> f64 {
        self.scale
    }
}

/// Builds a mesh whose vertices are keyed by an exact position, so faces
/// that meet share their vertices.
#[derive(Default)]
struct SharedVertices {
    vertices: Vec<DVec3>,
    index: HashMap<[u64; 3], u32>,
}

impl SharedVertices {
    /// The index of vertex `v`, added if new.
    fn at(&mut self, v: DVec3) -> u32 {
        let key = v.to_array().map(|x| (x + 0.0).to_bits());
        *self.index.entry(key).or_insert_with(|| {
            self.vertices.push(v);
            self.vertices.len() as u32 - 1
        })
    }
}

/// An icosahedron on the unit sphere, each triangle split in four
/// `subdivisions` times (midpoints pushed out to the sphere).
fn icosphere(subdivisions: u32) -> LocalMesh {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut vertices: Vec<DVec3> = [
        [-1.0, phi, 0.0],
        [1.0, phi, 0.0],
        [-1.0, -phi, 0.0],
        [1.0, -phi, 0.0],
        [0.0, -1.0, phi],
        [0.0, 1.0, phi],
        [0.0, -1.0, -phi],
        [0.0, 1.0, -phi],
        [phi, 0.0, -1.0],
        [phi, 0.0, 1.0],
        [-phi, 0.0, -1.0],
        [-phi, 0.0, 1.0],
    ]
    .iter()
    .map(|&v| DVec3::from(v).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints: HashMap<[u32; 2], u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<DVec3>| {
            *midpoints.entry([a.min(b), a.max(b)]).or_insert_with(|| {
                vertices.push((vertices[a as usize] + vertices[b as usize]).normalize());
                vertices.len() as u32 - 1
            })
        };
        triangles = triangles
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = midpoint(a, b, &mut vertices);
                let bc = midpoint(b, c, &mut vertices);
                let ca = midpoint(c, a, &mut vertices);
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    LocalMesh { vertices, triangles }
}

/// A torus about z: `around` × `tube` quads, each split in two.
fn torus(major: f64, minor: f64, around: u32, tube: u32) -> LocalMesh {
    let vertex = |i: u32, j: u32| {
        let (theta, phi) = (
            std::f64::consts::TAU * f64::from(i % around) / f64::from(around),
            std::f64::consts::TAU * f64::from(j % tube) / f64::from(tube),
        );
        let r = major + minor * phi.cos();
        DVec3::new(r * theta.cos(), r * theta.sin(), minor * phi.sin())
    };
    let index = |i: u32, j: u32| (i % around) * tube + j % tube;
    let vertices = (0..around)
        .flat_map(|i| (0..tube).map(move |j| vertex(i, j)))
        .collect();
    let triangles = (0..around)
        .flat_map(|i| {
            (0..tube).flat_map(move |j| {
                let (a, b, c, d) = (index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1));
                [[a, b, c], [a, c, d]]
            })
        })
        .collect();
    LocalMesh { vertices, triangles }
}

/// The cube `[−1, 1]³`, each face an `n × n` grid of quads split in two.
fn cube_grid(n: u32) -> LocalMesh {
    let mut shared = SharedVertices::default();
    let mut triangles = Vec::new();
    let step = |i: u32| -1.0 + 2.0 * f64::from(i) / f64::from(n);
    // Each face: its normal axis, side and the two axes spanning it, in the
    // order that makes (u, v, normal) right-handed on the outward side.
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            let (u_axis, v_axis) = ((axis + 1) % 3, (axis + 2) % 3);
            let point = |i: u32, j: u32| {
                let mut p = [0.0; 3];
                p[axis] = side;
                p[u_axis] = step(i);
                p[v_axis] = step(j);
                DVec3::from(p)
            };
            for i in 0..n {
                for j in 0..n {
                    let [a, b, c, d] = [point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)]
                        .map(|p| shared.at(p));
                    let quad = if side > 0.0 {
                        [[a, b, c], [a, c, d]]
                    } else {
                        [[a, c, b], [a, d, c]]
                    };
                    triangles.extend(quad);
                }
            }
        }
    }
    LocalMesh {
        vertices: shared.vertices,
        triangles,
    }
}

/// A cylinder about z of `radius` from `−half_length` to `half_length`, its
/// side `sides` quads split in two, its ends fans around their centres.
fn cylinder(radius: f64, half_length: f64, sides: u32) -> LocalMesh {
    let rim = |i: u32, z: f64| {
        let a = std::f64::consts::TAU * f64::from(i % sides) / f64::from(sides);
        DVec3::new(radius * a.cos(), radius * a.sin(), z)
    };
    let mut vertices: Vec<DVec3> = (0..sides).map(|i| rim(i, -half_length)).collect();
    vertices.extend((0..sides).map(|i| rim(i, half_length)));
    vertices.push(DVec3::new(0.0, 0.0, -half_length));
    vertices.push(DVec3::new(0.0, 0.0, half_length));
    let (bottom, top) = (2 * sides, 2 * sides + 1);
    let mut triangles = Vec::new();
    for i in 0..sides {
        let next = (i + 1) % sides;
        let (a, b, c, d) = (i, next, sides + next, sides + i);
        triangles.extend([[a, b, c], [a, c, d], [bottom, next, i], [top, d, c]]);
    }
    LocalMesh { vertices, triangles }
}

/// A regular tetrahedron around the origin.
fn tetrahedron() -> LocalMesh {
    let vertices = [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ]
    .map(|v| DVec3::from(v) / 3f64.sqrt())
    .to_vec();
    LocalMesh {
        vertices,
        triangles: vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every mesh is closed and consistently wound: each edge has exactly two
    /// triangles, which run along it in opposite directions; and every
    /// triangle faces away from the inside.
    #[test]
    fn every_mesh_is_closed_and_faces_out() {
        for shape in ClosedShape::ALL {
            let mesh = ClosedMesh::new(shape, 1.0, DVec3::ZERO);
            let mut directed: HashMap<[u32; 2], u32> = HashMap::new();
            for t in &mesh.triangles {
                for k in 0..3 {
                    *directed.entry([t[k], t[(k + 1) % 3]]).or_default() += 1;
                }
                let [a, b, c] = t.map(|i| mesh.vertices[i as usize].as_dvec3());
                let centroid = (a + b + c) / 3.0;
                let outward = centroid - mesh.inside_towards(centroid);
                assert!((b - a).cross(c - a).dot(outward) > 0.0, "{shape:?} {t:?}");
            }
            for (&[a, b], &n) in &directed {
                assert_eq!(n, 1, "{shape:?}: edge {a}-{b} twice in one direction");
                assert_eq!(directed.get(&[b, a]), Some(&1), "{shape:?}: edge {a}-{b} open");
            }
            assert!(mesh.edges().iter().all(|(_, on)| on.len() == 2));
        }
    }
}
