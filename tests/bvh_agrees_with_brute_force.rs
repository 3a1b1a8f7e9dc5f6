//! The BVH returns the same nearest hit (primitive, t, u, v) as brute force,
//! single-ray and packet traversal agree lane by lane, and any-hit agrees with
//! nearest-hit on hit or miss: 10⁵ random and 10⁵ primary rays per scene, for
//! random scenes of every primitive type and for mixed scenes.

mod bvh_support;

use raypack::scene::generate::random;

#[test]
fn spheres() {
    bvh_support::check_scene("spheres", &random::random_spheres(1000, 1), 101);
}

#[test]
fn triangles() {
    bvh_support::check_scene("triangles", &random::random_triangles(1000, 2), 102);
}

#[test]
fn polygons() {
    bvh_support::check_scene("polygons", &random::random_polygons(1000, 3), 103);
}

#[test]
fn transformed() {
    bvh_support::check_scene("transformed", &random::random_transformed(600, 4), 104);
}

#[test]
fn mixed_with_planes() {
    bvh_support::check_scene("mixed", &random::random_mixed(1000, 5), 105);
}

#[test]
fn closed_mesh() {
    // Shared edges and vertices everywhere: ties between neighbours must resolve
    // to the lower index, as in brute force.
    bvh_support::check_scene("mesh", &random::bumpy_sphere(2000, 6), 106);
}
