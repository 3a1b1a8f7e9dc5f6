//! What the subcommands share: the SCENE argument, image sizes, thread pools,
//! cameras and the run's environment. Subcommands import from here and from
//! [`crate::cli`]'s error types only, never from each other.

use std::path::Path;
use std::sync::OnceLock;
use std::time::Instant;

use crate::camera::Camera;
use crate::cli::error::CliError;
use crate::engines::NotApplicable;
use crate::geometry::triangle::TriangleTest;
use crate::scene::generate::test_scenes;
use crate::scene::{self, Scene};

/// Parse `WxH` into a non-empty image size.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=65536).contains(&n))
            .ok_or_else(|| format!("expected a size from 1 to 65536, got {v:?}"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// A thread pool of `threads` workers (all cores when None).
pub fn thread_pool(threads: Option<u16>) -> Result<rayon::ThreadPool, CliError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.map_or(0, usize::from))
        .build()
        .map_err(|e| CliError::Failed(anyhow::anyhow!("cannot start the worker threads: {e}")))
}

/// Load the scene a SCENE argument names (a file, or `gen:NAME[:N[:SEED]]` for
/// a scene generated in code, see [`test_scenes::from_spec`]), with the
/// seconds it took; a file that cannot be read, or a generated scene spelled
/// wrong, is the user's to fix (exit 2).
pub fn load_scene(arg: &Path) -> Result<(Scene, f64), CliError> {
    let start = Instant::now();
    let mut scene = match arg.to_str().and_then(test_scenes::from_spec) {
        Some(generated) => generated.map_err(|e| CliError::BadInput(anyhow::anyhow!(e)))?,
        None => scene::load(arg).map_err(|e| CliError::BadInput(e.into()))?,
    };
    scene.set_triangle_test(triangle_test());
    Ok((scene, start.elapsed().as_secs_f64()))
}

/// The triangle test of the command line (`--triangle`), which [`load_scene`]
/// puts every triangle under; set once, by `cli::main`.
static TRIANGLE_TEST: OnceLock<TriangleTest> = OnceLock::new();

/// Set the triangle test of every scene [`load_scene`] loads from now on
/// (once; a later call changes nothing).
pub fn set_triangle_test(test: TriangleTest) {
    // Set once by main before any scene loads; a second call has nothing to change.
    let _ = TRIANGLE_TEST.set(test);
}

/// The triangle test [`load_scene`] uses: the command line's, else the default.
pub fn triangle_test() -> TriangleTest {
    TRIANGLE_TEST.get().copied().unwrap_or_default()
}

/// The scene's camera (or a default one that frames it) at `size` or its own resolution.
pub fn scene_camera(scene: &Scene, path: &Path, size: Option<(u32, u32)>) -> Result<Camera, CliError> {
    let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
    let (w, h) = size.unwrap_or((spec.width, spec.height));
    spec.camera_at(w, h)
        .map_err(|e| CliError::BadInput(anyhow::anyhow!("{}: {e}", path.display())))
}

/// Bytes a render keeps per pixel, at most: the frame's colour (12), its
/// 8-bit image (3), the annotated picture with a heat map beside it (6), the
/// heat map's values (8), per-pixel traversal costs (8), the encoded PNG (3),
/// rounded up for the caption band and slack.
pub const BYTES_PER_PIXEL: u64 = 48;

/// Memory the image buffers may take where the system does not say how much is
/// available (no `/proc/meminfo`): 16 GiB.
const FALLBACK_MEMORY: u64 = 16 << 30;

/// The memory available to a new allocation: Linux's `MemAvailable`.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Refuse, before any work, an image of `width × height` whose buffers
/// ([`BYTES_PER_PIXEL`] each) would not fit in the memory available, so a huge
/// `--size` is a clear error (exit 2) rather than an aborted allocation; say
/// on stderr how large a large one is, since it may run for minutes.
pub fn check_image_memory(width: u32, height: u32) -> Result<(), CliError> {
    let (available, source) = match available_memory() {
        Some(m) => (m, "MemAvailable"),
        None => (FALLBACK_MEMORY, "raypack's cap where the system does not say"),
    };
    image_fits(width, height, available, source).map_err(|e| CliError::BadInput(anyhow::anyhow!(e)))?;
    let pixels = u64::from(width) * u64::from(height);
    if pixels >= 1 << 24 {
        eprintln!(
            "note: rendering {width}x{height} ({:.0} M pixels, about {:.1} GB of buffers)",
            pixels as f64 / 1e6,
            (pixels * BYTES_PER_PIXEL) as f64 / 1e9
        );
    }
    Ok(())
}

/// Whether the buffers of a `width × height` image fit in `available` bytes
/// (as `source` counts them); the refusal says by how much they do not.
fn image_fits(width: u32, height: u32, available: u64, source: &str) -> Result<(), String> {
    let needed = u64::from(width) * u64::from(height) * BYTES_PER_PIXEL;
    let gb = |b: u64| b as f64 / 1e9;
    if needed > available {
        return Err(format!(
            "a {width}x{height} image needs about {:.1} GB for its buffers ({BYTES_PER_PIXEL} B per pixel), \
             more than the {:.1} GB of memory available ({source}): render a smaller --size",
            gb(needed),
            gb(available)
        ));
    }
    Ok(())
}

/// An engine's failure to make its device or build: the user's to fix (exit
/// 2) where the engine cannot do what was asked ([`NotApplicable`]: its
/// kinds of primitives, its packet widths) or is missing from this build, else
/// a failure of the run.
pub fn engine_error(e: anyhow::Error) -> CliError {
    if e.is::<NotApplicable>() || e.is::<crate::scene::InstanceError>() {
        CliError::BadInput(e)
    } else {
        CliError::Failed(e)
    }
}

/// The scene's primitives in world space under their ids, instanced ones as
/// copies ([`Scene::flat_primitives`](crate::scene::Scene::flat_primitives)):
/// what `stats` counts on and `trace`'s queries other than the nearest read.
/// `reader` names who needs them, for the error when the copies would be too many.
pub fn flat_primitives<'s>(
    scene: &'s crate::scene::Scene,
    reader: &str,
) -> Result<&'s [crate::geometry::Primitive], CliError> {
    scene.flat_primitives().map_err(|e| {
        CliError::BadInput(anyhow::Error::new(e).context(format!("{reader} reads every primitive as a copy")))
    })
}

/// raypack's arguments as given (without the program's name), for a
/// result to say how to run it again.
pub fn arguments() -> Vec<String> {
    std::env::args_os()
        .skip(1)
        .map(|a| a.to_string_lossy().into_owned())
        .collect()
}

/// The environment of this run, with Embree's version and device
/// configuration when `embree_config` is given and the build has Embree.
pub fn environment(embree_config: Option<&str>) -> Result<crate::environment::Environment, CliError> {
    let env = crate::environment::Environment {
        triangle_test: triangle_test().name().to_string(),
        ..crate::environment::Environment::collect()
    };
    #[cfg(feature = "embree")]
    if let Some(config) = embree_config {
        let device = crate::embree::Device::new(config).map_err(|e| CliError::BadInput(e.into()))?;
        return Ok(env.with_embree((&device).into()));
    }
    #[cfg(not(feature = "embree"))]
    let _ = embree_config;
    Ok(env)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_larger_than_memory_are_refused_and_small_ones_pass() {
        let four_gb = 4_000_000_000;
        assert!(image_fits(64, 64, four_gb, "test").is_ok());
        assert!(image_fits(8000, 8000, four_gb, "test").is_ok());
        let msg = image_fits(65536, 65536, four_gb, "test").unwrap_err();
        assert!(
            msg.contains("206.2 GB") && msg.contains("4.0 GB") && msg.contains("--size"),
            "{msg}"
        );
        assert!(image_fits(20000, 20000, four_gb, "test").is_err());
        // This machine's own check passes a small image.
        assert!(check_image_memory(64, 64).is_ok());
    }

    #[test]
    fn sizes_parse_and_bad_ones_say_what_was_expected() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        assert_eq!(parse_size("8X8"), Ok((8, 8)));
        for bad in ["640", "0x10", "10x0", "axb", "70000x1"] {
            let e = parse_size(bad).unwrap_err();
            assert!(e.contains("expected"), "{bad}: {e}");
        }
    }
}
