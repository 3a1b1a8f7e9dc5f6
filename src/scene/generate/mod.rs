//! Scene generators, written as NFF text: the seven scenes of Eric Haines' Standard
//! Procedural Databases ("A Proposal for Standard Graphics Environments", IEEE
//! CG&A 7(11), 1987; `teapot` from SPD 3.0, 1990), written here from their
//! published descriptions, so their published ray statistics apply; the three
//! later SPD additions without published statistics (`lattice`, `shells`,
//! `jacks`); and three
//! families that scale smoothly from 10² to 10⁶ primitives of one known kind.
//!
//! | kind | `--size` means | default | primitives |
//! | --- | --- | --- | --- |
//! | `sphereflake` (SPD `balls`) | SPD size factor (recursion depth) | 4 | `Σ_{i≤n} 9^i` spheres + 1 polygon (7382) |
//! | `tetra` | SPD size factor | 4 | `4^(n+2)` triangles (4096) |
//! | `fractal-mountain` (SPD `mount`) | SPD size factor | 4 | `2·4^(n+2)` triangles + 4 spheres (8196) |
//! | `gears` | SPD size factor | 4 | `146·n³` polygons + the floor (9345) |
//! | `rings` | SPD size factor | 7 | `5n(n+1)(2n+1)` cylinders and as many spheres + 1 polygon (8401) |
//! | `tree` | SPD size factor | 11 | `2^(n+1) − 1` cones and as many spheres + 1 polygon (8191) |
//! | `teapot` | SPD size factor | 12 | `64n² − 8n` smooth triangles + `n²` polygons (9264) |
//! | `lattice` | SPD size factor | 12 | `(n+1)³` spheres + `3n(n+1)²` cylinders (8281) |
//! | `shells` | SPD size factor | 5 | `180·2ⁿ + 1` spheres (5761) |
//! | `jacks` | SPD size factor | 1 | `9·(8ⁿ − 1)/7`: 3 cylinders + 6 spheres per jack (9) |
//! | `random-spheres` | sphere count | 10000 | `n` spheres |
//! | `random-triangles` | triangle count | 10000 | `n` triangles |
//! | `terrain` | subdivision level | 6 | `2·4^n` triangles (8192) |
//! | `forest` | instance count | 1000 | `n` instances of 2 meshes (about 24,000 unique triangles) + 2 ground triangles |
//! | `city` | instance count | 1000 | `n` instances of 4 towers (about 34,000 unique triangles) + 2 ground triangles |
//!
//! `forest` and `city` are instanced (copies of a few meshes, [`forest`],
//! [`city`]): NFF
//! cannot hold instances, so it is written as glTF
//! ([`gltf_writer`](crate::scene::gltf_writer)), as is any kind made of
//! triangles only when the output file asks for `.glb` or `.gltf`.
//!
//! The SPD size factors of balls, tetra and mount follow the 1987 distribution,
//! where 4 is the classic scene (SPD 3.x renumbered tetra and mount: its 6 is
//! this 4); rings, tree and teapot keep the SPD's own factors, whose defaults
//! above give the primitive counts of its published statistics, and lattice,
//! shells and jacks the SPD's own factors and defaults.
//! The random kinds and the terrain are seeded with [`crate::rng::Rng`]; the
//! mountain's `--seed` is the SPD's mountain number. Each file starts with `#`
//! comments saying what it is and the command that made it.

pub mod city;
pub mod closed_mesh;
pub mod forest;
mod gears;
mod jacks;
mod lattice;
mod lots;
mod mountain;
pub mod nff_writer;
pub mod random;
mod random_spheres;
mod random_triangles;
mod rings;
mod shells;
mod sphereflake;
mod studio;
mod teapot;
mod terrain;
pub mod test_scenes;
mod tetra;
mod tree;

use std::io::{self, Write};
use std::ops::RangeInclusive;
use std::path::Path;

use nff_writer::NffWriter;

use crate::scene::{Scene, nff};

/// Seed of the random kinds when none is given.
const DEFAULT_SEED: u64 = 1;

/// Largest primitive count of the random kinds.
const MAX_COUNT: u32 = 10_000_000;

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum Kind {
    /// SPD `balls`: the sphereflake, mirror spheres on a floor.
    #[value(alias = "balls")]
    Sphereflake,
    /// SPD `tetra`: a Sierpinski tetrahedron of triangles.
    Tetra,
    /// SPD `mount`: a fractal mountain of triangles and 4 glass spheres.
    #[value(alias = "mount")]
    FractalMountain,
    /// SPD `gears`: an array of meshed gears, some of glass, over a mirror floor.
    Gears,
    /// SPD `rings`: a pyramid of objects of 6 pentagonal rings of cylinders and spheres.
    Rings,
    /// SPD `tree`: a branching tree of cones and spheres over a field.
    Tree,
    /// SPD `teapot`: the Newell teapot's patches as smooth triangles on a checkerboard.
    Teapot,
    /// SPD `lattice`: shiny spheres joined by matte cylinders in a cubic lattice.
    Lattice,
    /// SPD `shells`: a spiral seashell of overlapping spheres.
    Shells,
    /// SPD `jacks`: a jack of cylinders and spheres with smaller jacks in its octants, recursively.
    Jacks,
    /// Spheres at random in a cube.
    RandomSpheres,
    /// Triangles at random in a cube.
    RandomTriangles,
    /// A diamond-square height field of triangles.
    Terrain,
    /// A forest of trees and rocks, instances of two meshes (glTF only: NFF has no instances).
    Forest,
    /// A city of towers with recessed windows, instances of four meshes (glTF only).
    City,
}

impl Kind {
    /// Every kind, in the order of the table above.
    pub const ALL: [Kind; 15] = [
        Kind::Sphereflake,
        Kind::Tetra,
        Kind::FractalMountain,
        Kind::Gears,
        Kind::Rings,
        Kind::Tree,
        Kind::Teapot,
        Kind::Lattice,
        Kind::Shells,
        Kind::Jacks,
        Kind::RandomSpheres,
        Kind::RandomTriangles,
        Kind::Terrain,
        Kind::Forest,
        Kind::City,
    ];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Sphereflake => "sphereflake",
            Kind::Tetra => "tetra",
            Kind::FractalMountain => "fractal-mountain",
            Kind::Gears => "gears",
            Kind::Rings => "rings",
            Kind::Tree => "tree",
            Kind::Teapot => "teapot",
            Kind::Lattice => "lattice",
            Kind::Shells => "shells",
            Kind::Jacks => "jacks",
            Kind::RandomSpheres => "random-spheres",
            Kind::RandomTriangles => "random-triangles",
            Kind::Terrain => "terrain",
            Kind::Forest => "forest",
            Kind::City => "city",
        }
    }

    /// Whether this is one of the Standard Procedural Databases, written from
    /// its published description (its `--size` is the SPD size factor).
    pub fn is_spd(self) -> bool {
        matches!(
            self,
            Kind::Sphereflake
                | Kind::Tetra
                | Kind::FractalMountain
                | Kind::Gears
                | Kind::Rings
                | Kind::Tree
                | Kind::Teapot
                | Kind::Lattice
                | Kind::Shells
                | Kind::Jacks
        )
    }

    /// What `--size` means.
    pub fn size_meaning(self) -> &'static str {
        match self {
            Kind::RandomSpheres => "the number of spheres",
            Kind::RandomTriangles => "the number of triangles",
            Kind::Terrain => "the subdivision level",
            Kind::Forest | Kind::City => "the number of instances",
            spd => {
                debug_assert!(spd.is_spd());
                "the SPD size factor"
            }
        }
    }

    /// The `--size` values accepted (the largest give a few million primitives).
    pub fn sizes(self) -> RangeInclusive<u32> {
        match self {
            Kind::Sphereflake => 0..=7,
            Kind::Tetra => 0..=9,
            Kind::FractalMountain => 0..=8,
            Kind::Gears => 1..=20,
            Kind::Rings => 1..=50,
            Kind::Tree => 0..=20,
            Kind::Teapot => 1..=200,
            Kind::Lattice => 1..=60,
            Kind::Shells => 0..=12,
            Kind::Jacks => 1..=7,
            Kind::RandomSpheres | Kind::RandomTriangles => 1..=MAX_COUNT,
            Kind::Terrain => 0..=10,
            Kind::Forest => 1..=forest::MAX_INSTANCES,
            Kind::City => 1..=city::MAX_INSTANCES,
        }
    }

    /// `--size` when none is given: the classic SPD scenes, about 10⁴ primitives otherwise.
    pub fn default_size(self) -> u32 {
        match self {
            Kind::Sphereflake | Kind::Tetra | Kind::FractalMountain | Kind::Gears => 4,
            Kind::Rings => 7,
            Kind::Tree => 11,
            Kind::Teapot | Kind::Lattice => 12,
            Kind::Shells => 5,
            Kind::Jacks => 1,
            Kind::RandomSpheres | Kind::RandomTriangles => 10_000,
            Kind::Terrain => 6,
            Kind::Forest | Kind::City => 1000,
        }
    }

    /// The `--seed` values accepted; None for kinds that are not random.
    pub fn seeds(self) -> Option<RangeInclusive<u64>> {
        match self {
            Kind::FractalMountain => Some(0..=mountain::MAX_MOUNTAIN),
            Kind::RandomSpheres | Kind::RandomTriangles | Kind::Terrain | Kind::Forest | Kind::City => {
                Some(0..=u64::MAX)
            }
            // Every other SPD scene is fixed.
            spd => {
                debug_assert!(spd.is_spd());
                None
            }
        }
    }

    /// Whether the scene is made of instances, which NFF cannot hold (it is
    /// written as glTF).
    pub fn is_instanced(self) -> bool {
        matches!(self, Kind::Forest | Kind::City)
    }

    /// `--seed` when none is given.
    pub fn default_seed(self) -> Option<u64> {
        // Only kinds that take a seed have a default one.
        self.seeds()?;
        Some(match self {
            Kind::FractalMountain => mountain::DEFAULT_MOUNTAIN,
            _ => DEFAULT_SEED,
        })
    }
}

/// Why a scene cannot be generated.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GenerateError {
    /// A size outside [`Kind::sizes`].
    #[error("{kind}: --size {size} is out of range: {meaning} must be {min} to {max}")]
    SizeOutOfRange {
        /// Kind name.
        kind: &'static str,
        /// The size asked for.
        size: u32,
        /// What the size means.
        meaning: &'static str,
        /// Smallest accepted.
        min: u32,
        /// Largest accepted.
        max: u32,
    },
    /// A seed for a kind that is not random.
    #[error("{0} is not random: it takes no --seed")]
    NotRandom(&'static str),
    /// A seed outside [`Kind::seeds`].
    #[error("{kind}: --seed {seed} is out of range (0 to {max})")]
    SeedOutOfRange {
        /// Kind name.
        kind: &'static str,
        /// The seed asked for.
        seed: u64,
        /// Largest accepted.
        max: u64,
    },
}

/// A checked request: kind, size and seed. 24 bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Params {
    /// What to generate.
    pub kind: Kind,
    /// Size, as [`Kind::size_meaning`] says.
    pub size: u32,
    /// Seed (None for kinds that are not random).
    pub seed: Option<u64>,
}

impl Params {
    /// Check a request, filling in the defaults.
    pub fn new(kind: Kind, size: Option<u32>, seed: Option<u64>) -> Result<Self, GenerateError> {
        let size = size.unwrap_or(kind.default_size());
        let sizes = kind.sizes();
        if !sizes.contains(&size) {
            return Err(GenerateError::SizeOutOfRange {
                kind: kind.name(),
                size,
                meaning: kind.size_meaning(),
                min: *sizes.start(),
                max: *sizes.end(),
            });
        }
        let seed = match (kind.seeds(), seed) {
            (None, Some(_)) => return Err(GenerateError::NotRandom(kind.name())),
            (Some(seeds), Some(seed)) if !seeds.contains(&seed) => {
                return Err(GenerateError::SeedOutOfRange {
                    kind: kind.name(),
                    seed,
                    max: *seeds.end(),
                });
            }
            (_, Some(seed)) => Some(seed),
            (_, None) => kind.default_seed(),
        };
        Ok(Self { kind, size, seed })
    }

    /// How many primitives the scene has.
    pub fn primitive_count(&self) -> u64 {
        match self.kind {
            Kind::Sphereflake => sphereflake::primitive_count(self.size),
            Kind::Tetra => tetra::primitive_count(self.size),
            Kind::FractalMountain => mountain::primitive_count(self.size),
            Kind::Gears => gears::primitive_count(self.size),
            Kind::Rings => rings::primitive_count(self.size),
            Kind::Tree => tree::primitive_count(self.size),
            Kind::Teapot => teapot::primitive_count(self.size),
            Kind::Lattice => lattice::primitive_count(self.size),
            Kind::Shells => shells::primitive_count(self.size),
            Kind::Jacks => jacks::primitive_count(self.size),
            Kind::RandomSpheres | Kind::RandomTriangles => u64::from(self.size),
            Kind::Terrain => terrain::primitive_count(self.size),
            Kind::Forest | Kind::City => self.scene().id_count(),
        }
    }

    /// The command that writes this scene to stdout.
    pub fn command(&self) -> String {
        let mut command = format!("raypack gen {} --size {}", self.kind.name(), self.size);
        if let Some(seed) = self.seed {
            command += &format!(" --seed {seed}");
        }
        command
    }

    /// One line saying what the scene is.
    pub fn title(&self) -> String {
        let (n, count) = (self.size, self.primitive_count());
        let seed = self.seed.unwrap_or_default();
        match self.kind {
            Kind::Sphereflake => format!(
                "SPD `balls` (sphereflake), size factor {n}: {} mirror spheres + 1 floor polygon, 3 lights",
                count - 1
            ),
            Kind::Tetra => {
                format!("SPD `tetra` (Sierpinski tetrahedron), size factor {n}: {count} triangles, 1 light")
            }
            Kind::FractalMountain => format!(
                "SPD `mount` (fractal mountain no. {seed}), size factor {n}: {} triangles + 4 glass spheres, 1 light",
                count - 4
            ),
            Kind::Gears => format!(
                "SPD `gears`, size factor {n}: {} meshed gears (one in five glass) of 146 polygons + 1 floor polygon, 5 lights",
                (count - 1) / 146
            ),
            Kind::Rings => format!(
                "SPD `rings`, size factor {n}: {} cylinders + as many spheres (6 rings of 5 per object) + 1 wall polygon, 3 lights",
                (count - 1) / 2
            ),
            Kind::Tree => format!(
                "SPD `tree`, size factor {n}: {} branches (cones + spheres) + 1 field polygon, 7 lights",
                (count - 1) / 2
            ),
            Kind::Teapot => format!(
                "SPD `teapot`, size factor {n}: {} smooth triangles + {} checkerboard polygons, 2 lights",
                count - u64::from(n * n),
                n * n
            ),
            Kind::Lattice => {
                let spheres = u64::from(n + 1).pow(3);
                format!(
                    "SPD `lattice`, size factor {n}: {spheres} shiny spheres + {} matte cylinders, 6 lights",
                    count - spheres
                )
            }
            Kind::Shells => format!("SPD `shells`, size factor {n}: {count} spheres on a spiral, 1 light"),
            Kind::Jacks => format!(
                "SPD `jacks`, size factor {n}: {} jacks of 3 cylinders + 6 spheres, 1 light",
                count / 9
            ),
            Kind::RandomSpheres => format!("{count} random spheres in [-1, 1]^3, seed {seed}, 3 lights"),
            Kind::RandomTriangles => format!("{count} random triangles in [-1, 1]^3, seed {seed}, 3 lights"),
            Kind::Terrain => {
                format!("diamond-square terrain, level {n}: {count} triangles, seed {seed}, 1 light")
            }
            Kind::Forest => format!(
                "forest of {n} instances of 2 meshes (trees and rocks): {count} instanced triangles, seed {seed}, 1 light"
            ),
            Kind::City => format!(
                "city of {n} instances of 4 towers: {count} instanced triangles, seed {seed}, 1 light"
            ),
        }
    }

    /// Write the scene as NFF to `out`, header comments first; returns `out`
    /// (flushed) for the caller to finish. An instanced kind
    /// ([`Kind::is_instanced`]) is refused: NFF has no instances.
    pub fn write_nff<W: Write>(&self, out: W) -> io::Result<W> {
        if self.kind.is_instanced() {
            return Err(io::Error::new(
                io::ErrorKind::Unsupported,
                format!(
                    "{} is instanced, which NFF cannot hold: write it as glTF (-o FILE.glb or FILE.gltf)",
                    self.kind.name()
                ),
            ));
        }
        let mut nff = NffWriter::new(out);
        nff.comment(&self.title())?;
        nff.comment(&format!("Made by: {}", self.command()))?;
        if self.kind.is_spd() {
            nff.comment(
                "Written from the published description of Eric Haines' Standard Procedural Databases.",
            )?;
        }
        let seed = self.seed.unwrap_or_default();
        match self.kind {
            Kind::Sphereflake => sphereflake::write(self.size, &mut nff)?,
            Kind::Tetra => tetra::write(self.size, &mut nff)?,
            Kind::FractalMountain => mountain::write(self.size, seed, &mut nff)?,
            Kind::Gears => gears::write(self.size, &mut nff)?,
            Kind::Rings => rings::write(self.size, &mut nff)?,
            Kind::Tree => tree::write(self.size, &mut nff)?,
            Kind::Teapot => teapot::write(self.size, &mut nff)?,
            Kind::Lattice => lattice::write(self.size, &mut nff)?,
            Kind::Shells => shells::write(self.size, &mut nff)?,
            Kind::Jacks => jacks::write(self.size, &mut nff)?,
            Kind::RandomSpheres => random_spheres::write(self.size, seed, &mut nff)?,
            Kind::RandomTriangles => random_triangles::write(self.size, seed, &mut nff)?,
            Kind::Terrain => terrain::write(self.size, seed, &mut nff)?,
            Kind::Forest | Kind::City => unreachable!("refused above"),
        }
        debug_assert_eq!(nff.primitives(), self.primitive_count(), "{:?}", self);
        nff.finish()
    }

    /// The scene as NFF text. Panics for an instanced kind
    /// ([`Kind::is_instanced`]), which has none.
    pub fn to_nff(&self) -> String {
        let bytes = self
            .write_nff(Vec::new())
            .expect("an NFF kind, written to memory");
        String::from_utf8(bytes).expect("NFF output is ASCII")
    }

    /// The scene: an instanced kind made directly, the others read back
    /// from their NFF text (so both hold the same primitives in the same order).
    pub fn scene(&self) -> Scene {
        match self.kind {
            Kind::Forest => forest::forest(self.size as usize, self.seed.unwrap_or(DEFAULT_SEED)),
            Kind::City => city::city(self.size as usize, self.seed.unwrap_or(DEFAULT_SEED)),
            _ => nff::parse(Path::new(&self.command()), self.to_nff().as_bytes())
                .expect("the generators write NFF their reader takes"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_the_classic_scenes() {
        let p = Params::new(Kind::FractalMountain, None, None).unwrap();
        assert_eq!((p.size, p.seed, p.primitive_count()), (4, Some(21), 8196));
        assert_eq!(p.command(), "raypack gen fractal-mountain --size 4 --seed 21");
        assert_eq!(
            Params::new(Kind::Sphereflake, None, None)
                .unwrap()
                .primitive_count(),
            7382
        );
        assert_eq!(
            Params::new(Kind::Tetra, None, None).unwrap().primitive_count(),
            4096
        );
        // SPD 3.4's published counts for rings, tree and teapot.
        for (kind, count) in [(Kind::Rings, 8401), (Kind::Tree, 8191), (Kind::Teapot, 9264)] {
            assert_eq!(
                Params::new(kind, None, None).unwrap().primitive_count(),
                count,
                "{kind:?}"
            );
        }
    }

    #[test]
    fn bad_sizes_and_seeds_are_refused() {
        assert!(matches!(
            Params::new(Kind::Sphereflake, Some(8), None),
            Err(GenerateError::SizeOutOfRange { max: 7, .. })
        ));
        assert!(matches!(
            Params::new(Kind::RandomSpheres, Some(0), None),
            Err(GenerateError::SizeOutOfRange { min: 1, .. })
        ));
        assert_eq!(
            Params::new(Kind::Tetra, None, Some(3)),
            Err(GenerateError::NotRandom("tetra"))
        );
        assert!(matches!(
            Params::new(Kind::FractalMountain, None, Some(1 << 20)),
            Err(GenerateError::SeedOutOfRange { .. })
        ));
    }
}
