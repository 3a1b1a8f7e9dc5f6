//! The SCENE argument of `check` and `trace`: a scene file (read by
//! [`scene::load`]), or `gen:NAME[:N[:SEED]]` for a scene generated in code
//! ([`test_scenes`]).

use std::path::Path;

use crate::cli::CliError;
use crate::compare::test_scenes;
use crate::scene::{self, Scene};

/// Load the scene `arg` names; a file that cannot be read is bad input.
pub fn load_scene(arg: &str) -> Result<Scene, CliError> {
    match test_scenes::from_spec(arg) {
        Some(generated) => generated.map_err(|e| CliError::BadInput(anyhow::anyhow!(e))),
        None => scene::load(Path::new(arg)).map_err(|e| CliError::BadInput(anyhow::anyhow!(e.to_string()))),
    }
}
