//! An instanced scene whose triangles are large on screen: a city of `n`
//! towers on a grid of streets, every tower one of four meshes (a box whose
//! facades are grids of recessed windows) placed by a quarter turn about the
//! vertical, a stretch of its height and a translation, seen from a street
//! corner. Where the forest's canopies are thousands of triangles in a few
//! pixels, here a window near the camera covers many packets: the scene on
//! which coherent rays through instances stay coherent. Memory grows with the
//! instance count and the four meshes (some 34,000 triangles), not with the
//! instanced triangles: `gen:city:120000` holds about 10⁹.

use std::f32::consts::FRAC_PI_2;

use glam::{Mat4, Quat, Vec3};

use crate::geometry::{Primitive, Triangle};
use crate::rng::Rng;
use crate::scene::generate::lots::{Lots, diffuse};
use crate::scene::{CameraSpec, Light, Material, Mesh, Scene};

/// Most instances `raypack gen city` makes: with every one the largest tower
/// (12,552 triangles) the ids stay within 32 bits.
pub const MAX_INSTANCES: u32 = 200_000;

/// Width of a facade cell (one window and the wall around it).
const CELL_WIDTH: f32 = 3.0;

/// Height of a storey.
const STOREY: f32 = 3.5;

/// How far a window sits behind its facade.
const RECESS: f32 = 0.3;

/// Distance between neighbouring lots: the widest tower (18) and a street.
const SPACING: f32 = 32.0;

/// The four towers: (storeys, window columns on each side).
const TOWERS: [(usize, usize); 4] = [(6, 4), (12, 5), (20, 6), (30, 4)];

/// Materials: the ground, each tower's walls, the windows.
const GROUND: u32 = 0;
const WINDOWS: u32 = 5;

/// The city of `n` towers from `seed`, seen from above one corner of its streets.
pub fn city(n: usize, seed: u64) -> Scene {
    let mut rng = Rng::new(seed);
    let mut scene = Scene {
        source: format!("generated:city:{n}:{seed}"),
        background: Vec3::new(0.6, 0.72, 0.88),
        materials: vec![
            diffuse(Vec3::new(0.35, 0.35, 0.37)),
            diffuse(Vec3::new(0.75, 0.68, 0.55)),
            diffuse(Vec3::new(0.6, 0.62, 0.66)),
            diffuse(Vec3::new(0.7, 0.45, 0.35)),
            diffuse(Vec3::new(0.85, 0.85, 0.8)),
            Material {
                color: Vec3::new(0.15, 0.2, 0.3),
                kd: 0.5,
                ks: 0.5,
                shine: 60.0,
                ..Material::default()
            },
        ],
        ..Scene::default()
    };
    let lots = Lots::new(n, SPACING);
    let extent = lots.extent;
    lots.push_ground(&mut scene, GROUND);
    let towers: Vec<u32> = (0..TOWERS.len()).map(|k| scene.add_mesh(tower(k))).collect();
    for k in 0..n {
        let jitter = Vec3::new(rng.range(-2.0, 2.0), 0.0, rng.range(-2.0, 2.0));
        let at = lots.centre(k) + jitter;
        let turn = Quat::from_rotation_y(FRAC_PI_2 * rng.below(4) as f32);
        let stretch = Vec3::new(1.0, rng.range(0.8, 1.25), 1.0);
        let mesh = towers[rng.below(TOWERS.len() as u32) as usize];
        scene
            .place(mesh, Mat4::from_scale_rotation_translation(stretch, turn, at))
            .expect("a city's transforms are invertible, its ids few");
    }
    scene.lights.push(Light {
        position: Vec3::new(-0.3 * extent, 2.0 * extent.max(200.0), -0.1 * extent),
        color: Vec3::ONE,
    });
    // From outside one corner, above the low towers, across the blocks.
    let eye = Vec3::new(-2.5 * SPACING, 70.0, -1.5 * SPACING);
    scene.camera = Some(CameraSpec {
        eye,
        center: Vec3::new(0.5 * extent, 15.0, 0.5 * extent),
        up: Vec3::Y,
        fovx: 60.0,
        fovy: 60.0,
        width: 512,
        height: 512,
    });
    scene
}

/// Tower `k` of [`TOWERS`]: four facades of recessed windows and a flat
/// roof, closed but for its floor, its footprint centred on the origin,
/// standing on y = 0. Its walls are material `k + 1`.
fn tower(k: usize) -> Mesh {
    let (storeys, columns) = TOWERS[k];
    let half = 0.5 * columns as f32 * CELL_WIDTH;
    let height = storeys as f32 * STOREY;
    let mut mesh = Mesh {
        name: format!("tower{k}"),
        ..Mesh::default()
    };
    let mut push = |t: Triangle, material: u32| {
        mesh.primitives.push(Primitive::Triangle(t));
        mesh.material_of.push(material);
    };
    // Each facade by its left corner on the ground, the direction along it
    // and its outward normal; each one's right corner is the next one's left,
    // written with the same numbers, so the corners' edges are shared exactly.
    let facades = [
        (Vec3::new(-half, 0.0, half), Vec3::X, Vec3::Z),
        (Vec3::new(half, 0.0, half), Vec3::NEG_Z, Vec3::X),
        (Vec3::new(half, 0.0, -half), Vec3::NEG_X, Vec3::NEG_Z),
        (Vec3::new(-half, 0.0, -half), Vec3::Z, Vec3::NEG_X),
    ];
    let wall = k as u32 + 1;
    for (origin, along, out) in facades {
        // A point of the facade: `s` along it, `y` up, `depth` behind it.
        let at = |s: f32, y: f32, depth: f32| origin + along * s + Vec3::Y * y - out * depth;
        let mut quad = |[a, b, c, d]: [Vec3; 4], material: u32| {
            push(Triangle::new(a, b, c), material);
            push(Triangle::new(a, c, d), material);
        };
        for storey in 0..storeys {
            for column in 0..columns {
                // The cell's grid: its sides and its window's opening, so
                // that every edge ends where its neighbours' do.
                let (s0, y0) = (column as f32 * CELL_WIDTH, storey as f32 * STOREY);
                let (s1, y1) = (s0 + CELL_WIDTH, y0 + STOREY);
                let (s, y) = ([s0, s0 + 0.6, s1 - 0.6, s1], [y0, y0 + 0.8, y1 - 0.6, y1]);
                // The wall: the grid's eight squares around the opening.
                for (a, b) in (0..3).flat_map(|a| (0..3).map(move |b| (a, b))) {
                    if (a, b) != (1, 1) {
                        let corners = [(0, 0), (1, 0), (1, 1), (0, 1)];
                        quad(corners.map(|(i, j)| at(s[a + i], y[b + j], 0.0)), wall);
                    }
                }
                // The opening's reveals (sill, head, jambs), then the glass:
                // corners as (s, y, depth).
                let (w0, w1, v0, v1, r) = (s[1], s[2], y[1], y[2], RECESS);
                let opening = [
                    ([(w0, v0, 0.0), (w0, v0, r), (w1, v0, r), (w1, v0, 0.0)], wall),
                    ([(w0, v1, r), (w0, v1, 0.0), (w1, v1, 0.0), (w1, v1, r)], wall),
                    ([(w0, v0, 0.0), (w0, v1, 0.0), (w0, v1, r), (w0, v0, r)], wall),
                    ([(w1, v0, r), (w1, v1, r), (w1, v1, 0.0), (w1, v0, 0.0)], wall),
                    ([(w0, v0, r), (w0, v1, r), (w1, v1, r), (w1, v0, r)], WINDOWS),
                ];
                for (corners, material) in opening {
                    quad(corners.map(|(s, y, depth)| at(s, y, depth)), material);
                }
            }
        }
        // The roof: a fan from its middle to every vertex of the facade's top edge.
        let top: Vec<f32> = (0..columns)
            .flat_map(|c| {
                let s0 = c as f32 * CELL_WIDTH;
                [s0, s0 + 0.6, s0 + CELL_WIDTH - 0.6]
            })
            .chain([columns as f32 * CELL_WIDTH])
            .collect();
        let middle = Vec3::new(0.0, height, 0.0);
        for pair in top.windows(2) {
            push(
                Triangle::new(middle, at(pair[1], height, 0.0), at(pair[0], height, 0.0)),
                wall,
            );
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Triangles of tower `k`: 26 a window cell (8 wall squares, 4 reveals,
    /// the glass) and the roof's 3 a column, on four sides.
    fn tower_triangles(k: usize) -> usize {
        let (storeys, columns) = TOWERS[k];
        4 * (storeys * columns * 26 + 3 * columns)
    }

    #[test]
    fn a_city_holds_its_towers_once() {
        let c = city(400, 3);
        assert_eq!(c.primitives.len(), 2, "the ground");
        let summary = c.instancing_summary().unwrap();
        assert_eq!((summary.instances, summary.meshes), (400, TOWERS.len()));
        let unique: usize = (0..TOWERS.len()).map(tower_triangles).sum();
        assert_eq!(
            summary.unique_primitives,
            unique as u64 + 2,
            "the towers and the ground"
        );
        let smallest = tower_triangles(0) as u64;
        assert!(summary.instanced_primitives > 400 * smallest, "{summary:?}");
        assert!(c.camera.unwrap().camera().is_ok());
        assert_eq!(city(400, 3).id_count(), c.id_count(), "seeded");
        let largest = (0..TOWERS.len()).map(tower_triangles).max().unwrap() as u64;
        assert!(
            u64::from(MAX_INSTANCES) * largest < u64::from(u32::MAX),
            "ids fit 32 bits"
        );
    }

    #[test]
    fn a_tower_is_closed_but_for_its_floor() {
        // Every edge of a tower is shared by exactly two of its triangles,
        // but the four along the ground: the facades meet exactly.
        use std::collections::HashMap;
        for k in 0..TOWERS.len() {
            let mesh = tower(k);
            let mut edges: HashMap<[[u32; 3]; 2], usize> = HashMap::new();
            for p in &mesh.primitives {
                let Primitive::Triangle(t) = p else {
                    panic!("triangles only")
                };
                let v = t.vertices().map(|v| v.to_array().map(f32::to_bits));
                for (a, b) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
                    *edges.entry(if a < b { [a, b] } else { [b, a] }).or_default() += 1;
                }
            }
            let open: Vec<_> = edges.iter().filter(|&(_, &n)| n != 2).collect();
            let on_ground = open
                .iter()
                .all(|&(e, n)| *n == 1 && e.iter().all(|v| f32::from_bits(v[1]) == 0.0));
            assert!(on_ground, "tower {k}: {} open edges off the ground", open.len());
        }
    }
}
