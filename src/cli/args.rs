//! What the subcommands share: the SCENE argument, image sizes, thread pools,
//! cameras and Embree scenes. Subcommands import from here and from
//! [`crate::cli`]'s error types only, never from each other.

use std::path::Path;
use std::time::Instant;

use crate::camera::Camera;
use crate::cli::CliError;
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
    let scene = match arg.to_str().and_then(test_scenes::from_spec) {
        Some(generated) => generated.map_err(|e| CliError::BadInput(anyhow::anyhow!(e)))?,
        None => scene::load(arg).map_err(|e| CliError::BadInput(e.into()))?,
    };
    Ok((scene, start.elapsed().as_secs_f64()))
}

/// The scene's camera (or a default one that frames it) at `size` or its own resolution.
pub fn scene_camera(scene: &Scene, path: &Path, size: Option<(u32, u32)>) -> Result<Camera, CliError> {
    let spec = scene.camera.unwrap_or_else(|| scene.default_camera());
    let (w, h) = size.unwrap_or((spec.width, spec.height));
    spec.camera_at(w, h)
        .map_err(|e| CliError::BadInput(anyhow::anyhow!("{}: {e}", path.display())))
}

/// The Embree scene of `scene` on a device made with `config`.
#[cfg(feature = "embree")]
pub fn embree_scene(
    scene: &Scene,
    config: &str,
    mode: crate::engine::EmbreeMode,
) -> Result<crate::embree::EmbreeScene, CliError> {
    use crate::embree::{Device, EmbreeScene};
    use crate::engine::EmbreeMode;
    let device = std::sync::Arc::new(Device::new(config).map_err(|e| CliError::BadInput(e.into()))?);
    match mode {
        EmbreeMode::Robust => EmbreeScene::robust(device, &scene.primitives),
        EmbreeMode::Fast => EmbreeScene::new(device, &scene.primitives),
    }
    .map_err(|e| CliError::Failed(e.into()))
}

#[cfg(test)]
mod tests {
    use super::*;

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
