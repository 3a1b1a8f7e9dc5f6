//! The SCENE argument of every subcommand: a scene file (read by
//! [`scene::load`]), or `gen:NAME[:N[:SEED]]` for a scene generated in code:
//! one of the [`test_scenes`] (N primitives), or else a kind of `raypack gen`
//! ([`generate::Kind`], N its `--size`, SEED its `--seed`), read from the NFF
//! text the generator writes, exactly as `raypack gen NAME > file` would be.

use std::path::Path;

use clap::ValueEnum;

use crate::cli::CliError;
use crate::compare::test_scenes;
use crate::scene::generate::{Kind, Params};
use crate::scene::{self, Scene, nff};

/// Load the scene `arg` names; a file that cannot be read, or a generated
/// scene spelled wrong, is bad input.
pub fn load_scene(arg: &Path) -> Result<Scene, CliError> {
    let spec = arg.to_str();
    if let Some(generated) = spec.and_then(generated_nff) {
        return generated.map_err(CliError::BadInput);
    }
    match spec.and_then(test_scenes::from_spec) {
        Some(generated) => generated.map_err(|e| CliError::BadInput(anyhow::anyhow!(e))),
        None => scene::load(arg).map_err(|e| CliError::BadInput(e.into())),
    }
}

/// The scene of `gen:KIND[:SIZE[:SEED]]` when KIND is a `raypack gen` kind
/// that is not also a test-scene name; None otherwise.
fn generated_nff(spec: &str) -> Option<anyhow::Result<Scene>> {
    let mut parts = spec.strip_prefix("gen:")?.split(':');
    let name = parts.next()?;
    if test_scenes::NAMES.contains(&name) {
        return None;
    }
    let kind = Kind::from_str(name, true).ok()?;
    let number = |part: Option<&str>, what: &str| -> anyhow::Result<Option<u64>> {
        part.map(|p| {
            p.parse::<u64>()
                .map_err(|_| anyhow::anyhow!("{spec}: {what} must be a whole number, got `{p}`"))
        })
        .transpose()
    };
    Some((|| {
        let size = number(parts.next(), "the size")?;
        let seed = number(parts.next(), "the seed")?;
        if parts.next().is_some() {
            anyhow::bail!("{spec}: expected gen:{name}[:SIZE[:SEED]]");
        }
        let size = size
            .map(|s| u32::try_from(s).map_err(|_| anyhow::anyhow!("{spec}: the size {s} is out of range")))
            .transpose()?;
        let params = Params::new(kind, size, seed).map_err(|e| anyhow::anyhow!("{spec}: {e}"))?;
        Ok(nff::parse(Path::new(spec), params.to_nff().as_bytes())?)
    })())
}
