//! SPD `lattice` (A. Costa, SPD 3.1, 1993): shiny spheres on the points of a
//! cubic lattice, each joined to its neighbours by matte cylinders (red along
//! x, green along y, blue along z), lit by six lights around the unit cube.
//!
//! Size factor `n` puts `n + 1` spheres of radius `1/(4n)` along each edge of
//! the unit cube, `(n+1)³` in all, and `3·n·(n+1)²` cylinders of radius
//! `1/(16n)` between them; a cylinder stops just inside the two spheres it
//! joins. 1 → 20, 2 → 81, 5 → 756, 12 → 8281 (the SPD default).

use std::io::{self, Write};

use glam::DVec3;

use super::nff_writer::{NffWriter, Surface, View, phong_exponent};

/// Primitives for size factor `size`: the spheres and the cylinders.
pub fn primitive_count(size: u32) -> u64 {
    let (n, m) = (u64::from(size), u64::from(size) + 1);
    m * m * m + 3 * n * m * m
}

/// Write the scene for size factor `size` (at least 1).
pub fn write<W: Write>(size: u32, out: &mut NffWriter<W>) -> io::Result<()> {
    let n = f64::from(size);
    let step = 1.0 / n;
    let sphere_radius = 0.25 * step;
    let rod_radius = 0.0625 * step;
    // A rod starts 99% of the way from the sphere's centre to where it meets the sphere's surface.
    let inset = 0.99 * sphere_radius * (1.0 - (rod_radius / sphere_radius).sqrt());

    // Step 1: background, a camera looking down the lattice's diagonal, six lights.
    out.background(DVec3::new(0.078, 0.361, 0.753))?;
    let x = (f64::from(size / 2) + 0.5) * step;
    let z = 0.5 * step;
    out.view(&View {
        from: DVec3::new(x, 1.0, 1.0 - z),
        at: DVec3::new(x, -1.0, -1.0 - z),
        up: DVec3::new(0.2, 1.0, 0.0),
        angle: 60.0,
        hither: 0.01,
        resolution: [512, 512],
    })?;
    for light in [
        [2.0, 0.5, 0.5],
        [-1.0, 0.5, 0.5],
        [0.5, 2.0, 0.5],
        [0.5, -1.0, 0.5],
        [0.5, 0.5, 2.0],
        [0.5, 0.5, -1.0],
    ] {
        out.light(DVec3::from_array(light))?;
    }

    // Step 2: a sphere at every lattice point, a rod to each next point along x, y and z.
    let sphere = Surface {
        color: DVec3::splat(0.9),
        kd: 0.5,
        ks: 0.5,
        shine: phong_exponent(5.0),
        transmittance: 0.0,
        ior: 1.0,
    };
    let rod = |color: DVec3| Surface {
        kd: 0.99,
        ..Surface::matte(color)
    };
    let axes = [
        (DVec3::X, rod(DVec3::new(0.9, 0.1, 0.1))),
        (DVec3::Y, rod(DVec3::new(0.1, 0.9, 0.1))),
        (DVec3::Z, rod(DVec3::new(0.1, 0.1, 0.9))),
    ];
    for i in 0..=size {
        for j in 0..=size {
            for k in 0..=size {
                let index = [i, j, k];
                let p = DVec3::new(f64::from(i), f64::from(j), f64::from(k)) * step;
                out.surface(&sphere)?;
                out.sphere(p, sphere_radius)?;
                for (a, (axis, surface)) in axes.iter().enumerate() {
                    if index[a] == size {
                        continue;
                    }
                    out.surface(surface)?;
                    let base = p + inset * *axis;
                    let apex = p + (step - inset) * *axis;
                    out.cone(base, rod_radius, apex, rod_radius)?;
                }
            }
        }
    }
    Ok(())
}
