//! The robustness oracle: ray sets whose right answer is known by
//! construction, on closed meshes ([`ClosedMesh`]), grouped by category and
//! counted per engine. Agreement between two engines cannot see a crack both
//! share; these rays can, since each says what must happen:
//!
//! - *edges and vertices*: from inside each mesh through every shared vertex,
//!   every edge's midpoint and a random point of every edge, and from outside
//!   along the same lines inwards: each crosses the closed surface there, so
//!   each must hit there (a miss, or a hit on a far wall after slipping
//!   through, is a *leak*);
//! - *grazing*: from just under every edge, nearly along it and tilted out by
//!   10⁻² or 10⁻⁵: still inside, so they must hit;
//! - *spawned*: secondary rays ([`Ray::spawn`]) leaving the surface where an
//!   engine's own primary ray hit it, reflected, diffuse and towards a light,
//!   outwards from a convex mesh inside a copy of itself grown by 10⁻⁴ of the
//!   scene's scale: each must hit the copy, and a hit on the mesh it leaves is
//!   a *self-hit*;
//! - *far and small*: the edge and vertex rays with the mesh moved 10³, 10⁵
//!   and 10⁷ from the origin (sized 10⁻⁴ of that, at least 1) and shrunk to 10⁻⁶;
//! - *against f64*: random rays at and from inside each mesh, against the
//!   double-precision reference ([`reference_f64`]): a miss where it clearly
//!   hits is a leak, a hit where it clearly misses a *false hit*.
//!
//! Every category also gives each engine's t error against the reference's
//! t on the triangle the engine hit, in f32 ulps of that t or of the ray
//! origin's largest coordinate, whichever is larger (median, p99, max). [`queries`] checks the
//! all-hits and inside/outside queries ([`crate::accel::queries`]) the same way.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::accel::Bvh;
use crate::accel::queries::{all_hits, is_inside};
use crate::compare::agreement::Quantiles;
use crate::compare::reference_f64::{self, Nearest};
use crate::geometry::Primitive;
use crate::geometry::triangle::TriangleTest;
use crate::ray::{Hit, NO_HIT, Ray};
use crate::rng::Rng;
use crate::scene::generate::closed_mesh::{ClosedMesh, ClosedShape};

/// A group of rays with a known answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Category {
    /// Through shared edges and vertices, from inside and outside.
    EdgesVertices,
    /// Nearly parallel to an edge, from just inside.
    Grazing,
    /// Secondary rays leaving the surface.
    Spawned,
    /// Edges and vertices, far from the origin and tiny.
    FarSmall,
    /// Random rays against the f64 reference.
    AgainstF64,
}

impl Category {
    /// Every category, in table order.
    pub const ALL: [Category; 5] = [
        Category::EdgesVertices,
        Category::Grazing,
        Category::Spawned,
        Category::FarSmall,
        Category::AgainstF64,
    ];

    /// The name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Category::EdgesVertices => "edges-vertices",
            Category::Grazing => "grazing",
            Category::Spawned => "spawned",
            Category::FarSmall => "far-small",
            Category::AgainstF64 => "against-f64",
        }
    }
}

/// Where a mesh sits: `offset · (1, 0.7, 0.4)` from the origin, `scale` its size.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Placement {
    /// Name in tables.
    pub name: &'static str,
    /// Size of the mesh (1 is the shapes' own).
    pub scale: f64,
    /// Distance from the origin, along `(1, 0.7, 0.4)`.
    pub offset: f64,
}

impl Placement {
    /// At the origin, its own size.
    pub const ORIGIN: Placement = Placement {
        name: "origin",
        scale: 1.0,
        offset: 0.0,
    };

    /// The placements of the far-and-small category: moved 10³, 10⁵ and 10⁷
    /// away, sized 10⁻⁴ of the distance (at least 1), so that their finest
    /// features (the thin cylinder's radius) still span tens of f32 steps
    /// (which grow with the coordinates: 1 at 10⁷); and shrunk to 10⁻⁶ at the origin.
    pub const FAR_SMALL: [Placement; 4] = [
        Placement {
            name: "1e3",
            scale: 1.0,
            offset: 1e3,
        },
        Placement {
            name: "1e5",
            scale: 10.0,
            offset: 1e5,
        },
        Placement {
            name: "1e7",
            scale: 1000.0,
            offset: 1e7,
        },
        Placement {
            name: "1e-6",
            scale: 1e-6,
            offset: 0.0,
        },
    ];

    /// The world offset.
    fn offset(self) -> DVec3 {
        self.offset * DVec3::new(1.0, 0.7, 0.4)
    }
}

/// What a ray of the oracle must do.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Expect {
    /// Cross the closed surface: hit something.
    Hit,
    /// Cross the closed surface at `at`: its first hit lies within `within`
    /// of that point (a hit further off went through and hit a far wall).
    CrossAt {
        /// The point aimed at.
        at: DVec3,
        /// How far from it a hit may lie: half the way from the ray's
        /// inside point to it, well short of any other wall on the line.
        within: f64,
    },
    /// Whatever the f64 reference (its nearest hit, here) says.
    Reference(Nearest),
}

impl Expect {
    /// The point a ray was aimed at, if it was.
    fn aimed_at(&self) -> Option<DVec3> {
        match self {
            Expect::CrossAt { at, .. } => Some(*at),
            _ => None,
        }
    }
}

/// What a ray of the oracle did, against what it must.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// What it must.
    Right,
    /// It crossed a closed surface without a hit there (or missed where the
    /// reference clearly hits).
    Leak,
    /// It hit where the reference clearly misses.
    FalseHit,
}

/// What `hit`, the nearest hit of `ray`, is against `expect`.
fn outcome(expect: &Expect, ray: &Ray, hit: &Hit) -> Outcome {
    let missed = hit.prim == NO_HIT;
    match *expect {
        Expect::Hit if missed => Outcome::Leak,
        Expect::CrossAt { at, within } => {
            let point = ray.origin.as_dvec3() + f64::from(hit.t) * ray.dir.as_dvec3();
            if missed || point.distance(at) > within {
                Outcome::Leak
            } else {
                Outcome::Right
            }
        }
        Expect::Reference(want) if missed && want.surely_hit && !want.ambiguous => Outcome::Leak,
        Expect::Reference(want) if !missed && want.prim == NO_HIT => Outcome::FalseHit,
        _ => Outcome::Right,
    }
}

/// A mesh and rays through it with their answers.
struct Case {
    category: Category,
    shape: ClosedShape,
    placement: Placement,
    triangles: Vec<[Vec3; 3]>,
    rays: Vec<Ray>,
    expect: Vec<Expect>,
}

/// One engine's counts on one case: a row of the oracle's table.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Row {
    /// The category.
    pub category: Category,
    /// The mesh.
    pub shape: ClosedShape,
    /// Where it sits ([`Placement::name`], or `all` in totals).
    pub placement: String,
    /// The engine.
    pub engine: String,
    /// Rays traced.
    pub rays: usize,
    /// Rays that crossed a closed surface without a hit there (or missed
    /// where the reference clearly hits): [`Outcome::Leak`].
    pub leaks: usize,
    /// Hits where the reference clearly misses.
    pub false_hits: usize,
    /// Spawned rays that hit the surface they leave.
    pub self_hits: usize,
    /// t error in f32 ulps against the reference, where both hit.
    pub t_ulps: Quantiles,
}

/// An engine under test: a name and the nearest hit of each ray of a scene
/// of triangles (the scene, then the rays).
pub struct Engine<'a> {
    /// Its name in the table.
    pub name: String,
    /// Trace `rays` through the triangles (primitive `i` is triangle `i`).
    #[allow(clippy::type_complexity)]
    pub trace: Box<dyn Fn(&[[Vec3; 3]], &[Ray]) -> Vec<Hit> + Sync + 'a>,
}

/// How many rays the oracle draws where it samples (spawned, against f64),
/// per mesh and placement.
#[derive(Clone, Copy, Debug)]
pub struct Sizes {
    /// Primary rays whose hits spawn secondary rays (three each).
    pub spawn_points: usize,
    /// Random rays against the f64 reference.
    pub random_rays: usize,
}

impl Default for Sizes {
    fn default() -> Self {
        Self {
            spawn_points: 2_000,
            random_rays: 5_000,
        }
    }
}

/// Run every category on every shape with every engine: the table.
pub fn run(shapes: &[ClosedShape], engines: &[Engine], sizes: Sizes, seed: u64) -> Vec<Row> {
    let mut rows = Vec::new();
    for &shape in shapes {
        let origin = ClosedMesh::new(shape, 1.0, DVec3::ZERO);
        let mut cases = vec![
            edge_rays(&origin, Category::EdgesVertices, Placement::ORIGIN, seed),
            grazing_rays(&origin, seed),
            random_rays(&origin, sizes.random_rays, seed),
        ];
        for placement in Placement::FAR_SMALL {
            let mesh = ClosedMesh::new(shape, placement.scale, placement.offset());
            cases.push(edge_rays(&mesh, Category::FarSmall, placement, seed));
        }
        for case in &cases {
            for engine in engines {
                let hits = (engine.trace)(&case.triangles, &case.rays);
                rows.push(score(case, &engine.name, &hits));
            }
        }
        if spawns_outwards(shape) {
            for placement in std::iter::once(Placement::ORIGIN).chain(Placement::FAR_SMALL) {
                let mesh = ClosedMesh::new(shape, placement.scale, placement.offset());
                for engine in engines {
                    rows.push(spawned(&mesh, placement, engine, sizes.spawn_points, seed));
                }
            }
        }
    }
    rows
}

/// Shapes whose outward secondary rays meet nothing of their own (convex
/// ones): the torus sees itself.
fn spawns_outwards(shape: ClosedShape) -> bool {
    shape != ClosedShape::Torus
}

/// The triangles of a mesh as vertex triples.
fn triangles_of(mesh: &ClosedMesh) -> Vec<[Vec3; 3]> {
    mesh.triangles
        .iter()
        .map(|t| t.map(|i| mesh.vertices[i as usize]))
        .collect()
}

/// The ray from `from` through `to`, both rounded to f32 once.
fn ray_through(from: DVec3, to: DVec3) -> Ray {
    let origin = from.as_vec3();
    Ray::unbounded(origin, (to - origin.as_dvec3()).normalize().as_vec3())
}

/// The rays of the edges-and-vertices category on `mesh`: from inside
/// through every vertex, every edge's midpoint and one random point of
/// every edge, and from outside along the same lines inwards.
fn edge_rays(mesh: &ClosedMesh, category: Category, placement: Placement, seed: u64) -> Case {
    let mut rng = Rng::new(seed);
    let vertex = |i: u32| mesh.vertices[i as usize].as_dvec3();
    let mut targets: Vec<DVec3> = (0..mesh.vertices.len() as u32).map(vertex).collect();
    for ([a, b], _) in mesh.edges() {
        let (a, b) = (vertex(a), vertex(b));
        targets.push((a + b) / 2.0);
        targets.push(a + f64::from(rng.range(0.0, 1.0)) * (b - a));
    }
    let mut rays = Vec::with_capacity(2 * targets.len());
    let mut expect = Vec::with_capacity(2 * targets.len());
    for target in targets {
        let inside = mesh.inside_towards(target);
        rays.push(ray_through(inside, target));
        // As far again outside, looking back in.
        rays.push(ray_through(2.0 * target - inside, inside));
        // From outside, the next wall on the line lies beyond the inside
        // point; from inside there is none, or the torus's far side further
        // still: a hit within half the way to the inside point is at the target.
        let cross = Expect::CrossAt {
            at: target,
            within: 0.5 * target.distance(inside),
        };
        expect.extend([cross, cross]);
    }
    Case {
        category,
        shape: mesh.shape,
        placement,
        triangles: triangles_of(mesh),
        rays,
        expect,
    }
}

/// One ray of the edges-and-vertices category, as an engine answered it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AimedRay {
    /// The point of the surface it was aimed at: a vertex or a point of an edge.
    pub at: Vec3,
    /// From inside the mesh (else from outside, looking back in).
    pub from_inside: bool,
    /// [`Outcome::Right`] or [`Outcome::Leak`].
    pub outcome: Outcome,
}

/// The edges-and-vertices rays of `shape` at the origin, traced by
/// `engine`: the rays its row of that category and mesh counts, each with
/// where it was aimed and what it did.
pub fn edge_outcomes(shape: ClosedShape, engine: &Engine, seed: u64) -> Vec<AimedRay> {
    let mesh = ClosedMesh::new(shape, 1.0, DVec3::ZERO);
    let case = edge_rays(&mesh, Category::EdgesVertices, Placement::ORIGIN, seed);
    let hits = (engine.trace)(&case.triangles, &case.rays);
    case.rays
        .iter()
        .zip(&hits)
        .zip(&case.expect)
        .enumerate()
        .filter_map(|(i, ((ray, hit), expect))| {
            Some(AimedRay {
                at: expect.aimed_at()?.as_vec3(),
                // The rays alternate: from inside, then from outside.
                from_inside: i % 2 == 0,
                outcome: outcome(expect, ray, hit),
            })
        })
        .collect()
}

/// The grazing rays of `mesh`: from 10⁻³ of its size under each edge's
/// midpoint, along the edge, tilted outwards by 10⁻² and 10⁻⁵.
fn grazing_rays(mesh: &ClosedMesh, seed: u64) -> Case {
    let _ = seed;
    let vertex = |i: u32| mesh.vertices[i as usize].as_dvec3();
    let normal = |t: u32| {
        let [a, b, c] = mesh.triangles[t as usize].map(vertex);
        (b - a).cross(c - a).normalize_or_zero()
    };
    let mut rays = Vec::new();
    for ([a, b], faces) in mesh.edges() {
        let out = faces.iter().map(|&f| normal(f)).sum::<DVec3>().normalize();
        let (a, b) = (vertex(a), vertex(b));
        let start = (a + b) / 2.0 - 1e-3 * mesh.size() * out;
        for tilt in [1e-2, 1e-5] {
            for along in [b - a, a - b] {
                let dir = (along.normalize() + tilt * out).normalize();
                rays.push(Ray::unbounded(start.as_vec3(), dir.as_vec3()));
            }
        }
    }
    Case {
        category: Category::Grazing,
        shape: mesh.shape,
        placement: Placement::ORIGIN,
        triangles: triangles_of(mesh),
        expect: vec![Expect::Hit; rays.len()],
        rays,
    }
}

/// Random rays against the reference: from a sphere three sizes out towards
/// a point of the mesh's box, and from inside in any direction.
fn random_rays(mesh: &ClosedMesh, n: usize, seed: u64) -> Case {
    let mut rng = Rng::new(seed ^ 0xf64);
    let size = mesh.size() as f32;
    let rays = (0..n)
        .map(|i| {
            let target = size * rng.point_in(Vec3::splat(-1.2), Vec3::splat(1.2));
            if i % 2 == 0 {
                Ray::unbounded(
                    3.0 * size * rng.unit_vector(),
                    (target - 3.0 * size * rng.unit_vector()).normalize(),
                )
            } else {
                let inside = mesh.inside_towards(target.as_dvec3()).as_vec3();
                Ray::unbounded(inside, rng.unit_vector())
            }
        })
        .collect::<Vec<_>>();
    let triangles = triangles_of(mesh);
    let expect = rays
        .par_iter()
        .map(|ray| Expect::Reference(reference_f64::nearest(&triangles, ray)))
        .collect();
    Case {
        category: Category::AgainstF64,
        shape: mesh.shape,
        placement: Placement::ORIGIN,
        triangles,
        rays,
        expect,
    }
}

/// The error of `hit`'s t in f32 ulps (see [`reference_f64::ulps_from`])
/// against the f64 plane distance of the triangle it hit.
fn t_error(triangles: &[[Vec3; 3]], ray: &Ray, hit: &Hit) -> f64 {
    let [a, b, c] = triangles[hit.prim as usize];
    let reference = reference_f64::plane_t(a, b, c, ray);
    reference_f64::ulps_from(hit.t, reference, ray.origin.abs().max_element())
}

/// An engine's row on a case.
fn score(case: &Case, engine: &str, hits: &[Hit]) -> Row {
    let (mut leaks, mut false_hits) = (0, 0);
    let mut ulps = Vec::new();
    for ((hit, expect), ray) in hits.iter().zip(&case.expect).zip(&case.rays) {
        match outcome(expect, ray, hit) {
            Outcome::Leak => leaks += 1,
            Outcome::FalseHit => false_hits += 1,
            Outcome::Right => {}
        }
        if hit.prim != NO_HIT {
            ulps.push(t_error(&case.triangles, ray, hit));
        }
    }
    Row {
        category: case.category,
        shape: case.shape,
        placement: case.placement.name.to_string(),
        engine: engine.to_string(),
        rays: case.rays.len(),
        leaks,
        false_hits,
        self_hits: 0,
        t_ulps: Quantiles::of(ulps),
    }
}

/// The spawned category of one engine on `mesh`: `points` primary rays at
/// random points of its surface, and from each hit three secondary rays
/// outwards (reflected, diffuse, towards a light), in a scene of the mesh
/// and a copy of it grown by 10⁻⁴ of the scene's scale.
fn spawned(mesh: &ClosedMesh, placement: Placement, engine: &Engine, points: usize, seed: u64) -> Row {
    let mut rng = Rng::new(seed ^ 0x5a);
    let inner = triangles_of(mesh);
    // The scene's scale as the renderer takes it: its largest coordinate or extent.
    let offset = placement.offset();
    let scale = (offset.abs().max_element() + mesh.size()).max(2.0 * mesh.size());
    let gap = 1e-4 * scale;
    // The copy: each vertex moved out along its normal (the mean of its
    // faces') by three gaps, so that every face moves by one to three.
    let vertex = |i: u32| mesh.vertices[i as usize].as_dvec3();
    let mut normals = vec![DVec3::ZERO; mesh.vertices.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(vertex);
        let n = (b - a).cross(c - a).normalize_or_zero();
        t.iter().for_each(|&i| normals[i as usize] += n);
    }
    let shell: Vec<[Vec3; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| (vertex(i) + 3.0 * gap * normals[i as usize].normalize()).as_vec3()))
        .collect();
    let scene: Vec<[Vec3; 3]> = inner.iter().chain(&shell).copied().collect();
    // Primary rays at random points of random triangles, traced without the
    // shell (which would block them). Triangles that rounding to f32 flattened
    // (far from the origin, the thin cylinder's) are no target: their points
    // lie on a segment, which their neighbours may or may not cover.
    let targets: Vec<&[Vec3; 3]> = inner
        .iter()
        .filter(|&&[a, b, c]| !crate::geometry::Triangle::new(a, b, c).is_degenerate())
        .collect();
    let primaries: Vec<Ray> = (0..if targets.is_empty() { 0 } else { points })
        .map(|_| {
            let [a, b, c] = targets[rng.below(targets.len() as u32) as usize].map(Vec3::as_dvec3);
            let (u, v) = (f64::from(rng.range(0.05, 0.9)), f64::from(rng.range(0.05, 0.9)));
            let (u, v) = if u + v > 0.95 {
                (0.95 - v, 0.95 - u)
            } else {
                (u, v)
            };
            let target = a + u * (b - a) + v * (c - a);
            let n = (b - a).cross(c - a).normalize();
            let from = target + 2.0 * mesh.size() * (n + 0.5 * rng.unit_vector().as_dvec3()).normalize();
            ray_through(from, target)
        })
        .collect();
    let hits = (engine.trace)(&inner, &primaries);
    let mut secondaries = Vec::new();
    let mut leaks = 0;
    for (primary, hit) in primaries.iter().zip(&hits) {
        // It aims inside a triangle of a closed mesh: a miss is a leak.
        if hit.prim == NO_HIT {
            leaks += 1;
            continue;
        }
        let [a, b, c] = scene[hit.prim as usize];
        let n = (b - a).cross(c - a).normalize();
        let point = primary.at(hit.t);
        let reflected = primary.dir - 2.0 * primary.dir.dot(n) * n;
        let mut diffuse = rng.unit_vector();
        if diffuse.dot(n) < 0.0 {
            diffuse = -diffuse;
        }
        let light = point + 10.0 * mesh.size() as f32 * (n + 0.5 * rng.unit_vector()).normalize();
        for dir in [reflected, diffuse, (light - point).normalize()] {
            secondaries.push(Ray::spawn(point, n, dir, primary.origin, f32::INFINITY));
        }
    }
    let hits = (engine.trace)(&scene, &secondaries);
    let mut self_hits = 0;
    let mut ulps = Vec::new();
    for (hit, ray) in hits.iter().zip(&secondaries) {
        match hit.prim {
            NO_HIT => leaks += 1,
            p if (p as usize) < inner.len() => self_hits += 1,
            _ => ulps.push(t_error(&scene, ray, hit)),
        }
    }
    Row {
        category: Category::Spawned,
        shape: mesh.shape,
        placement: placement.name.to_string(),
        engine: engine.name.clone(),
        rays: primaries.len() + secondaries.len(),
        leaks,
        false_hits: 0,
        self_hits,
        t_ulps: Quantiles::of(ulps),
    }
}

/// The rows summed per category and engine (rays, leaks, false and self
/// hits added; the t error's median the largest median, its p99 and maximum
/// the largest).
pub fn totals(rows: &[Row]) -> Vec<Row> {
    let mut totals: Vec<Row> = Vec::new();
    for row in rows {
        match totals
            .iter_mut()
            .find(|t| t.category == row.category && t.engine == row.engine)
        {
            Some(t) => {
                t.rays += row.rays;
                t.leaks += row.leaks;
                t.false_hits += row.false_hits;
                t.self_hits += row.self_hits;
                t.t_ulps.p50 = t.t_ulps.p50.max(row.t_ulps.p50);
                t.t_ulps.p99 = t.t_ulps.p99.max(row.t_ulps.p99);
                t.t_ulps.max = t.t_ulps.max.max(row.t_ulps.max);
            }
            None => totals.push(Row {
                placement: "all".into(),
                ..row.clone()
            }),
        }
    }
    totals
}

/// How the queries built on nearest hits ([`queries`]) fared on one mesh
/// with one triangle test.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct QueryRow {
    /// The mesh, at the origin.
    pub shape: ClosedShape,
    /// The triangle test under the queries.
    pub test: TriangleTest,
    /// Points classified by [`is_inside`].
    pub points: usize,
    /// Points classified wrongly.
    pub wrong_inside: usize,
    /// Rays whose [`all_hits`] were counted.
    pub rays: usize,
    /// Rays with a wrong count of crossings: odd from outside or even from
    /// inside, or on a convex mesh more than one from inside or two from outside.
    pub wrong_crossings: usize,
}

/// The all-hits and inside/outside queries on each shape at the origin under
/// each triangle test, against answers known by construction: `n` points
/// just inside and just outside of random points of its faces, its edges
/// and its vertices (moved along the normal by 10⁻² or 10⁻³ of the
/// feature's size), each classified and the
/// start of a ray in a random direction whose crossings must have the
/// point's parity; and the edges-and-vertices rays, whose crossings a convex
/// mesh fixes exactly (one from inside, two from outside through it).
pub fn queries(shapes: &[ClosedShape], tests: &[TriangleTest], n: usize, seed: u64) -> Vec<QueryRow> {
    let mut rows = Vec::new();
    for &shape in shapes {
        let mesh = ClosedMesh::new(shape, 1.0, DVec3::ZERO);
        let points = near_surface_points(&mesh, n, seed);
        let mut rng = Rng::new(seed ^ 0xa11);
        let directions: Vec<Vec3> = points.iter().map(|_| rng.unit_vector()).collect();
        let edges = edge_rays(&mesh, Category::EdgesVertices, Placement::ORIGIN, seed);
        for &test in tests {
            let prims: Vec<Primitive> = mesh
                .primitives()
                .into_iter()
                .map(|mut p| {
                    p.set_triangle_test(test);
                    p
                })
                .collect();
            let bvh = Bvh::new(&prims);
            let wrong_inside = points
                .par_iter()
                .filter(|(p, inside)| is_inside(&bvh, &prims, *p) != *inside)
                .count();
            let parity = points
                .par_iter()
                .zip(&directions)
                .filter(|((p, inside), dir)| {
                    let crossings = all_hits(&bvh, &prims, &Ray::unbounded(*p, **dir)).len();
                    crossings % 2 != usize::from(*inside)
                        || (spawns_outwards(shape) && crossings > 1 + usize::from(!*inside))
                })
                .count();
            // The edge rays alternate: from inside (one crossing), from outside (two).
            let exact = edges
                .rays
                .par_iter()
                .enumerate()
                .filter(|(i, ray)| {
                    let crossings = all_hits(&bvh, &prims, ray).len();
                    let from_inside = i % 2 == 0;
                    if spawns_outwards(shape) {
                        crossings != if from_inside { 1 } else { 2 }
                    } else {
                        crossings % 2 != usize::from(from_inside)
                    }
                })
                .count();
            rows.push(QueryRow {
                shape,
                test,
                points: points.len(),
                wrong_inside,
                rays: points.len() + edges.rays.len(),
                wrong_crossings: parity + exact,
            });
        }
    }
    rows
}

/// `n` points near the surface of `mesh`, each with whether it is inside: a
/// random point of a random face, edge or vertex, moved along its normal
/// (for an edge or a vertex the mean of its faces') in or out by 10⁻² or
/// 10⁻³ of the feature's size (the face's shortest edge, the edge, the
/// vertex's shortest edge). Points on faces stay 10 such distances from
/// their edges and points on edges from their ends, so that the short move
/// crosses no other face (which, near a sharp vertex, a move inwards from
/// an edge would).
fn near_surface_points(mesh: &ClosedMesh, n: usize, seed: u64) -> Vec<(Vec3, bool)> {
    let mut rng = Rng::new(seed ^ 0x1b);
    let vertex = |i: u32| mesh.vertices[i as usize].as_dvec3();
    let face_normal = |t: u32| {
        let [a, b, c] = mesh.triangles[t as usize].map(vertex);
        (b - a).cross(c - a).normalize_or_zero()
    };
    let mut vertex_normals = vec![DVec3::ZERO; mesh.vertices.len()];
    let mut vertex_feature = vec![f64::INFINITY; mesh.vertices.len()];
    let edges = mesh.edges();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        tri.iter()
            .for_each(|&i| vertex_normals[i as usize] += face_normal(t as u32));
    }
    for ([a, b], _) in &edges {
        let length = vertex(*a).distance(vertex(*b));
        for i in [a, b] {
            vertex_feature[*i as usize] = vertex_feature[*i as usize].min(length);
        }
    }
    (0..n)
        .map(|_| {
            let fraction = if rng.below(2) == 0 { 1e-2 } else { 1e-3 };
            let (point, normal, feature) = match rng.below(3) {
                0 => {
                    let t = rng.below(mesh.triangles.len() as u32);
                    let [a, b, c] = mesh.triangles[t as usize].map(vertex);
                    let feature = a.distance(b).min(b.distance(c)).min(c.distance(a));
                    let margin = 10.0 * fraction * feature;
                    // A random point at least `margin` from each edge (else the centroid).
                    let point = (0..32)
                        .map(|_| {
                            let (u, v) = (f64::from(rng.range(0.0, 1.0)), f64::from(rng.range(0.0, 1.0)));
                            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
                            a + u * (b - a) + v * (c - a)
                        })
                        .find(|&p| {
                            [(a, b), (b, c), (c, a)]
                                .iter()
                                .all(|&(e0, e1)| distance_to_line(p, e0, e1) >= margin)
                        })
                        .unwrap_or((a + b + c) / 3.0);
                    (point, face_normal(t), feature)
                }
                1 => {
                    let ([a, b], faces) = &edges[rng.below(edges.len() as u32) as usize];
                    let (a, b) = (vertex(*a), vertex(*b));
                    let feature = a.distance(b);
                    // At least 10 moves from either end: s in [10·fraction, 1 − 10·fraction].
                    let s = 10.0 * fraction + (1.0 - 20.0 * fraction) * f64::from(rng.range(0.0, 1.0));
                    let normal = faces.iter().map(|&f| face_normal(f)).sum::<DVec3>();
                    (a + s * (b - a), normal, feature)
                }
                _ => {
                    let i = rng.below(mesh.vertices.len() as u32);
                    (vertex(i), vertex_normals[i as usize], vertex_feature[i as usize])
                }
            };
            let inside = rng.below(2) == 0;
            let side = if inside { -fraction } else { fraction } * feature;
            ((point + side * normal.normalize()).as_vec3(), inside)
        })
        .collect()
}

/// Distance from `p` to the line through `a` and `b`.
fn distance_to_line(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    (p - a).cross(b - a).length() / (b - a).length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::reference_f64::{TriangleAnswer, intersect_triangle};

    /// An intersector that refuses every ray within the reference's
    /// ambiguity of an edge: it leaks there, and only there.
    fn leaky() -> Engine<'static> {
        Engine {
            name: "leaky".into(),
            trace: Box::new(|triangles: &[[Vec3; 3]], rays: &[Ray]| {
                rays.iter()
                    .map(|ray| {
                        let mut hit = Hit::none(ray);
                        for (i, [a, b, c]) in triangles.iter().enumerate() {
                            if let TriangleAnswer::Hit(t) = intersect_triangle(*a, *b, *c, ray) {
                                hit.offer(t as f32, ray.t_min, i as u32);
                            }
                        }
                        hit
                    })
                    .collect()
            }),
        }
    }

    /// raypack's BVH under `test`, single rays.
    fn raypack(test: TriangleTest) -> Engine<'static> {
        Engine {
            name: test.name().into(),
            trace: Box::new(move |triangles: &[[Vec3; 3]], rays: &[Ray]| {
                let prims: Vec<Primitive> = triangles
                    .iter()
                    .map(|&[a, b, c]| {
                        Primitive::Triangle(crate::geometry::Triangle::new(a, b, c).with_test(test))
                    })
                    .collect();
                crate::compare::trace_rays(&Bvh::new(&prims), rays, crate::compare::Kernel::Scalar)
            }),
        }
    }

    /// The oracle catches a crack: the leaky intersector leaks in the edge
    /// category (and its far-and-small twin), and nowhere its random rays go;
    /// the watertight test leaks nowhere and hits itself nowhere.
    #[test]
    fn the_oracle_sees_a_leaky_intersector_and_not_a_watertight_one() {
        let sizes = Sizes {
            spawn_points: 200,
            random_rays: 500,
        };
        let engines = [leaky(), raypack(TriangleTest::Watertight)];
        let rows = run(
            &[ClosedShape::CubeGrid, ClosedShape::Tetrahedron],
            &engines,
            sizes,
            3,
        );
        let totals = totals(&rows);
        let total = |category, engine: &str| {
            totals
                .iter()
                .find(|r| r.category == category && r.engine == engine)
                .unwrap_or_else(|| panic!("no {category:?} row of {engine}"))
        };
        for category in [Category::EdgesVertices, Category::FarSmall] {
            let leaky = total(category, "leaky");
            assert!(leaky.leaks > leaky.rays / 2, "{leaky:?}");
        }
        assert_eq!(total(Category::AgainstF64, "leaky").leaks, 0);
        for category in Category::ALL {
            let watertight = total(category, "watertight");
            assert_eq!(
                (watertight.leaks, watertight.self_hits, watertight.false_hits),
                (0, 0, 0),
                "{watertight:?}"
            );
            assert!(watertight.rays > 0);
        }
    }

    /// An intersector that answers each ray with the farthest triangle it
    /// crosses, edges included: from outside it goes through the surface it
    /// was aimed at and stops at the far wall.
    fn farthest() -> Engine<'static> {
        Engine {
            name: "farthest".into(),
            trace: Box::new(|triangles: &[[Vec3; 3]], rays: &[Ray]| {
                rays.iter()
                    .map(|ray| {
                        let mut hit = Hit::none(ray);
                        for (i, [a, b, c]) in triangles.iter().enumerate() {
                            if let TriangleAnswer::Hit(t) | TriangleAnswer::Edge(t) =
                                intersect_triangle(*a, *b, *c, ray)
                            {
                                let t = t as f32;
                                if t > ray.t_min && (hit.prim == NO_HIT || t > hit.t) {
                                    hit.record(t, i as u32, 0.0, 0.0);
                                }
                            }
                        }
                        hit
                    })
                    .collect()
            }),
        }
    }

    /// A ray that slips through the edge it was aimed at and hits the far
    /// wall leaks: every ray from outside, and none from inside (where the
    /// target is the only wall).
    #[test]
    fn a_hit_on_the_far_wall_is_a_leak() {
        let rays = edge_outcomes(ClosedShape::Tetrahedron, &farthest(), 5);
        assert!(!rays.is_empty());
        for ray in &rays {
            let want = if ray.from_inside {
                Outcome::Right
            } else {
                Outcome::Leak
            };
            assert_eq!(ray.outcome, want, "{ray:?}");
        }
    }

    /// The per-ray outcomes that crack pictures draw are the rays the table
    /// counts: as many leaks as the mesh's row.
    #[test]
    fn edge_outcomes_leak_as_often_as_the_row_says() {
        let sizes = Sizes {
            spawn_points: 10,
            random_rays: 10,
        };
        let (shape, engine) = (ClosedShape::Tetrahedron, leaky());
        let rows = run(&[shape], std::slice::from_ref(&engine), sizes, 7);
        let row = rows
            .iter()
            .find(|r| r.category == Category::EdgesVertices)
            .expect("an edges-and-vertices row");
        let rays = edge_outcomes(shape, &engine, 7);
        let leaks = rays.iter().filter(|r| r.outcome == Outcome::Leak).count();
        assert_eq!((rays.len(), leaks), (row.rays, row.leaks));
        assert!(leaks > 0, "the leaky intersector leaks");
    }

    /// All hits and inside/outside under the watertight test match the
    /// construction on every mesh.
    #[test]
    fn the_queries_are_right_under_the_watertight_test() {
        for row in queries(&ClosedShape::ALL, &[TriangleTest::Watertight], 2_000, 4) {
            assert_eq!((row.wrong_inside, row.wrong_crossings), (0, 0), "{row:?}");
        }
    }
}
