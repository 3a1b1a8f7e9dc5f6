//! The SCENE argument of every subcommand: a scene file (read by
//! [`scene::load`]), or `gen:NAME[:N[:SEED]]` for a scene generated in code
//! ([`test_scenes`], or any kind of `raypack gen`, SPD scenes included).

use std::path::Path;

use crate::cli::CliError;
use crate::compare::test_scenes;
use crate::scene::{self, Scene};

/// Load the scene `arg` names; a file that cannot be read, or a generated
/// scene spelled wrong, is bad input.
pub fn load_scene(arg: &Path) -> Result<Scene, CliError> {
    match arg.to_str().and_then(test_scenes::from_spec) {
        Some(generated) => generated.map_err(|e| CliError::BadInput(anyhow::anyhow!(e))),
        None => scene::load(arg).map_err(|e| CliError::BadInput(e.into())),
    }
}
