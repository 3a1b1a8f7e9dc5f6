//! `raypack env [--json]`: the machine and the build that results are measured
//! on: CPU, cores, ISA extensions (compiled in and present), transparent huge
//! pages, rustc, profile, flags, git commit, Embree (with the `embree` feature)
//! and the date.

use crate::cli::CliResult;
use crate::environment::Environment;

/// Options of `env`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Embree device configuration to report (with the `embree` feature).
    #[arg(long, default_value = crate::engine::DEFAULT_EMBREE_CONFIG)]
    pub embree_config: String,
}

/// Collect the environment and print it.
pub fn run(args: Args) -> CliResult {
    let env = Environment::collect();
    // With Embree built in, make a device to ask the library its version.
    #[cfg(feature = "embree")]
    let env = {
        let device = crate::embree::Device::new(&args.embree_config)
            .map_err(|e| crate::cli::CliError::BadInput(e.into()))?;
        env.with_embree((&device).into())
    };
    if args.json {
        let text = serde_json::to_string_pretty(&env).map_err(anyhow::Error::from)?;
        println!("{text}");
    } else {
        for (name, value) in env.rows() {
            println!("{name:<12} {value}");
        }
    }
    Ok(())
}
