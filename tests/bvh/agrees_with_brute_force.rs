//! The BVH returns the same nearest hit (primitive, t, u, v) as brute force,
//! single-ray and packet traversal agree lane by lane, and any-hit agrees with
//! nearest-hit on hit or miss: 10⁵ random and 10⁵ primary rays per scene, for
//! random scenes of every primitive type and for mixed scenes.

use crate::support;
use raypack::accel::Bvh;
use raypack::geometry::{Primitive, TriangleTest};
use raypack::scene::generate::random;

#[test]
fn spheres() {
    support::bvh::check_scene("spheres", &random::random_spheres(1000, 1), 101);
}

#[test]
fn triangles() {
    support::bvh::check_scene("triangles", &random::random_triangles(1000, 2), 102);
}

// Polygons under both kernels, two tests (the slowest of this file, run side
// by side): the watertight pieces (held in the tree in their polygon's place,
// one item per piece) and the crossing test (one item per polygon). The
// pieces' scene has 400 polygons, not 1,000: brute force tests every piece of
// every polygon for each of the 4·10⁵ queries, and at 1,000 this one test
// took 72 s of CI's time.

#[test]
fn polygons_as_watertight_pieces() {
    let prims = random::random_polygons(400, 3);
    let pieces: usize = prims
        .iter()
        .map(|p| match p {
            Primitive::Polygon(p) => p.watertight_pieces().expect("random polygons are simple").len(),
            _ => 1,
        })
        .sum();
    assert!(
        pieces > 2 * prims.len(),
        "{pieces} pieces: too few to test the cut"
    );
    assert_eq!(Bvh::new(&prims).info().primitives, pieces);
    support::bvh::check_scene("polygons, pieces", &prims, 103);
}

#[test]
fn polygons_by_the_crossing_test() {
    let mut prims = random::random_polygons(1000, 3);
    for p in &mut prims {
        p.set_triangle_test(TriangleTest::Barycentric);
    }
    assert_eq!(Bvh::new(&prims).info().primitives, prims.len());
    support::bvh::check_scene("polygons, crossing test", &prims, 104);
}

#[test]
fn transformed() {
    support::bvh::check_scene("transformed", &random::random_transformed(600, 4), 104);
}

#[test]
fn mixed_with_planes() {
    support::bvh::check_scene("mixed", &random::random_mixed(1000, 5), 105);
}

#[test]
fn closed_mesh() {
    // Shared edges and vertices everywhere: ties between neighbours must resolve
    // to the lower index, as in brute force.
    support::bvh::check_scene("mesh", &random::bumpy_sphere(2000, 6), 106);
}

/// `BuildOptions::for_primitives`: small scenes of blocks get leaves of up to
/// one block priced per `SMALL_SCENE_PRICED_BLOCK` primitives, small scenes
/// with records leaves of up to 4, both a node cost of 1; then either kind
/// leaves of up to one block with node cost 1 (medium) and 2 (large), and the
/// defaults above (leaves of up to 16 in two blocks). Each tier starts at its
/// bound; `Bvh::new` picks the tier of its items' count and kind (blocks if
/// at most one item in 100 is of another kind); and trees
/// of the five tiers over the same mesh answer as brute force does, single
/// rays and packets.
#[test]
fn leaf_tiers() {
    use raypack::accel::bvh::LeafKind::{Blocks, Records};
    use raypack::accel::bvh::{
        BuildOptions, LARGE_SCENE_PRIMITIVES as LARGE, MEDIUM_SCENE_PRIMITIVES as MEDIUM,
        SMALL_BLOCK_SCENE_PRIMITIVES as SMALL_BLOCKS, SMALL_RECORD_SCENE_PRIMITIVES as SMALL_RECORDS,
        SMALL_SCENE_PRICED_BLOCK,
    };
    let key = |o: BuildOptions| (o.max_leaf_size, o.traversal_cost, o.block_size);
    let tiers = [
        (8, 1.0, SMALL_SCENE_PRICED_BLOCK),
        (4, 1.0, 8),
        (8, 1.0, 8),
        (8, 2.0, 8),
        (16, 2.0, 8),
    ];
    let [small_blocks, small_records, medium, large, defaults] = tiers;
    for (count, kind, tier) in [
        (1, Blocks, small_blocks),
        (SMALL_BLOCKS - 1, Blocks, small_blocks),
        (SMALL_BLOCKS, Blocks, medium),
        (1, Records, small_records),
        (SMALL_RECORDS - 1, Records, small_records),
        (SMALL_RECORDS, Records, medium),
        (MEDIUM - 1, Blocks, medium),
        (MEDIUM, Blocks, large),
        (MEDIUM, Records, large),
        (LARGE - 1, Records, large),
        (LARGE, Blocks, defaults),
        (LARGE, Records, defaults),
    ] {
        assert_eq!(
            key(BuildOptions::for_primitives(count, kind)),
            tier,
            "{count} {kind:?}"
        );
    }
    assert_eq!(
        BuildOptions::for_primitives(LARGE, Blocks),
        BuildOptions::default()
    );

    // A mesh, a cloud of spheres and a mesh beside a few spheres (one item in
    // 500) are built for blocks, a scene of four kinds for records.
    let mesh = random::bumpy_sphere(5_000, 7);
    let mut mesh_and_spheres = mesh.clone();
    mesh_and_spheres.extend(random::random_spheres(10, 10));
    for (name, prims, kind, other) in [
        ("mesh", &mesh, Blocks, Records),
        ("mesh and spheres", &mesh_and_spheres, Blocks, Records),
        ("spheres", &random::random_spheres(3_000, 8), Blocks, Records),
        ("mixed", &random::random_mixed(3_000, 9), Records, Blocks),
    ] {
        let built = Bvh::new(prims).info();
        let with =
            |kind| Bvh::with_options(prims, &BuildOptions::for_primitives(built.primitives, kind)).info();
        assert_eq!(built, with(kind), "{name}");
        assert_ne!(built, with(other), "{name}");
    }

    let rays = support::bvh::random_rays(support::bvh::scene_bounds(&mesh), 20_000, 107);
    let mut infos = Vec::new();
    for (max_leaf_size, traversal_cost, block_size) in tiers {
        let options = BuildOptions {
            max_leaf_size,
            traversal_cost,
            block_size,
            ..BuildOptions::default()
        };
        let bvh = Bvh::with_options(&mesh, &options);
        infos.push(bvh.info());
        support::bvh::check_rays(&mesh, &bvh, &rays, &format!("{options:?}"));
    }
    // Leaves of up to 4, of up to one block, and of more than one block;
    // priced per 4, more of them than priced per block.
    let largest: Vec<usize> = infos.iter().map(|i| i.max_leaf_size).collect();
    assert!(
        largest[1] <= 4 && [0, 2, 3].iter().all(|&t| (5..=8).contains(&largest[t])) && largest[4] > 8,
        "largest leaves {largest:?}"
    );
    assert!(infos[0].leaves > infos[2].leaves, "{infos:?}");
}

/// A polygon the tree holds as watertight pieces counts as its pieces when
/// `Bvh::new` picks its options: a scene of few polygons with many pieces
/// (an SPD gear's face is 142 triangles) is built as a scene of that many
/// triangles.
#[test]
fn polygons_count_as_their_pieces() {
    use glam::Vec3;
    use raypack::accel::bvh::{BuildOptions, LeafKind, SMALL_BLOCK_SCENE_PRIMITIVES as SMALL};
    use raypack::geometry::Polygon;
    // Star-shaped (concave) 40-gons, each 38 pieces, side by side.
    let star = |centre: Vec3| -> Vec<Vec3> {
        (0..40)
            .map(|i| {
                let angle = i as f32 * std::f32::consts::TAU / 40.0;
                let radius = if i % 2 == 0 { 1.0 } else { 0.6 };
                centre + radius * Vec3::new(angle.cos(), angle.sin(), 0.0)
            })
            .collect()
    };
    let polygons = SMALL / 38 + 1;
    let prims: Vec<Primitive> = (0..polygons)
        .map(|i| {
            let centre = Vec3::new((i % 64) as f32 * 3.0, (i / 64) as f32 * 3.0, 0.0);
            Primitive::Polygon(Polygon::new(&star(centre)).unwrap())
        })
        .collect();
    let bvh = Bvh::new(&prims);
    assert_eq!(bvh.len(), polygons * 38);
    assert!(prims.len() < SMALL && bvh.len() >= SMALL);
    // Built with the options of its pieces' count, not of its polygons'.
    let built_for = |count| {
        let options = BuildOptions::for_primitives(count, LeafKind::Blocks);
        Bvh::with_options(&prims, &options).info()
    };
    assert_eq!(bvh.info(), built_for(bvh.len()));
    assert_ne!(bvh.info(), built_for(prims.len()));
}

/// The scenes with which the fuzz target `pipeline` found single rays and
/// packets disagreeing (`tests/data/fuzz/pipeline_*.nff`), traced with the
/// fuzzer's rays (`fuzz/fuzz_targets/pipeline.rs`: 4×4 camera rays, and rays
/// from below the scene's box to the centres of the first 16 primitives'
/// boxes), every answer equal to brute force's. (Random rays from a box 10¹⁸
/// wide, as some of these scenes have, mean nothing in f32.)
#[test]
fn fuzz_pipeline_findings() {
    use raypack::accel::Bvh;
    use raypack::ray::Ray;
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz");
    let mut scenes = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if !(name.starts_with("pipeline_") && name.ends_with(".nff")) {
            continue;
        }
        let scene = raypack::scene::load(&path).unwrap();
        let bvh = Bvh::new(&scene.primitives);
        let mut rays = Vec::new();
        let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
        if let Ok(camera) = spec.camera_at(4, 4) {
            rays.extend((0..16).map(|k| camera.pixel_ray(k % 4, k / 4)));
        }
        let bounds = scene.bounds();
        let from = if bounds.is_empty() || !bounds.min.is_finite() {
            glam::Vec3::new(0.3, 0.7, 11.0)
        } else {
            bounds.min - glam::Vec3::ONE
        };
        rays.extend(
            (scene.primitives.iter())
                .filter_map(|p| p.bounds())
                .take(16)
                .filter_map(|b| (b.center() - from).try_normalize())
                .map(|dir| Ray::unbounded(from, dir)),
        );
        assert!(!rays.is_empty(), "{name}: no rays");
        support::bvh::check_rays(&scene.primitives, &bvh, &rays, &name);
        scenes += 1;
    }
    assert!(
        scenes >= 4,
        "only {scenes} pipeline findings in {}",
        dir.display()
    );
}
