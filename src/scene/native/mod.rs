//! The native scene format: TOML, for what NFF cannot say — the lecture's three
//! plane forms, transforms on any object or included file, named materials, and
//! a camera with separate horizontal and vertical fields of view.
//!
//! ```toml
//! background = [0.05, 0.05, 0.08]     # optional, default black
//!
//! [camera]                            # optional
//! eye = [0, 2, 8]
//! center = [0, 1, 0]
//! up = [0, 1, 0]                      # optional, default +y
//! fovx = 60                           # degrees, image edge to edge
//! fovy = 45
//! width = 640
//! height = 480
//!
//! [materials.red]                     # each field optional (NFF's default material)
//! color = [0.8, 0.1, 0.1]
//! kd = 0.7
//! ks = 0.3
//! shine = 40
//! transmittance = 0
//! ior = 1.5
//!
//! [[lights]]
//! position = [4, 6, 4]
//! color = [1, 1, 1]                   # optional, default white
//!
//! [meshes.gem]                        # optional: a file that `instance` objects place
//! path = "icosahedron.nff"
//! material = "red"                    # optional, default: the file's own
//!
//! [[objects]]                         # one primitive each, numbered in file order (includes after)
//! type = "sphere"                     # sphere | plane | triangle | polygon | cone | include | instance
//! center = [0, 1, 0]
//! radius = 1
//! inside_only = false                 # optional: NFF's negative radius
//! material = "red"                    # optional: a name under [materials]
//! transform = { scale = [1, 0.5, 1], rotate = { axis = [0, 0, 1], degrees = 30 }, translate = [0, 1, 0] }
//! ```
//!
//! Object fields by type (every object also takes `material` and `transform`):
//!
//! - `sphere`: `center`, `radius`, optional `inside_only`;
//! - `plane`, one of three forms: `implicit = [A, B, C, D]` (`Ax + By + Cz + D = 0`),
//!   `point` + `normal`, or `origin` + `i` + `j` (parametric `origin + u·i + v·j`);
//! - `triangle`: `vertices = [[x, y, z] ×3]`, optional `normals` (×3, smooth shading);
//! - `polygon`: `vertices` (≥ 3, planar, may be concave; the first three fix the normal);
//! - `cone`: `base`, `base_radius`, `apex`, `apex_radius` (no end caps);
//! - `include`: `path` of a scene file (relative to this file; any format
//!   [`scene::load`](crate::scene::load) reads), optional `keep_lights`. The
//!   file is an instance ([`instance`](crate::scene::instance)): its
//!   primitives are read once into a mesh, however often the file is
//!   included (with the same `material`), and each include places that mesh
//!   under its `transform`; a TOML file that includes in turn brings its own
//!   instances, their transforms composed with the include's. The mesh keeps
//!   its own materials unless `material` is given; the file's camera and
//!   background are ignored, and so are its lights unless `keep_lights = true`.
//!   Instanced primitives take the ids after the file's own primitives, in
//!   include order ([`Scene::locate`](crate::scene::Scene::locate)).
//!
//! - `instance`: `mesh`, the name of a mesh defined under `[meshes]`
//!   (`[meshes.tree]` with `path` and an optional `material`): the same as an
//!   `include` of that file, which each `instance` of it places again
//!   (an object's own `material` overrides the mesh's).
//!
//! A `transform` is either `matrix` (4×4, row-major, affine) or any of `scale`
//! (a number or `[sx, sy, sz]`), `rotate` (`{ axis, degrees }`) and `translate`,
//! applied in that order (M = T·R·S). A transformed sphere, cone or plane becomes
//! a [`Transformed`](crate::geometry::Transformed) primitive; triangles and
//! polygons are baked (their vertices transformed); an included file keeps its
//! primitives as they are, in its mesh.
//!
//! Errors name the file and the line of the offending value.
//!
//! The reader's files, bottom first:
//!
//! - `schema`: the tables as serde reads them (`TomlVec3`: a vector as written);
//! - `errors`: the line an error points at and how its message reads;
//! - `transform`: a `transform` table as a matrix, and primitives under it;
//! - `scene_files`: [`SceneFiles`], where includes come from;
//! - `reader`: the document turned into a [`Scene`](crate::scene::Scene),
//!   includes followed ([`load_from`], [`parse_from`]).

mod errors;
mod reader;
mod scene_files;
mod schema;
mod transform;

pub use errors::utf8_text;
pub use reader::{MAX_INCLUDE_DEPTH, load_from, parse_from};
pub use scene_files::SceneFiles;
