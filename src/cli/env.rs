//! `raypack env [--json]`: the machine and the build that results are measured
//! on: CPU, cores, ISA extensions (compiled in and present), transparent huge
//! pages, rustc, profile, flags, git commit, Embree (with the `embree` feature)
//! and the date; as text, also the engines this build links.

use crate::cli::args::environment;
use crate::cli::error::CliResult;
use crate::cli::stdout::outln;
use crate::engines::Engine;

/// Options of `env`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Embree device configuration to report (with the `embree` feature).
    #[arg(long, default_value = crate::embree_settings::DEFAULT_EMBREE_CONFIG)]
    pub embree_config: String,
}

/// Collect the environment and print it.
pub fn run(args: Args) -> CliResult {
    // With Embree built in, a device is made to ask the library its version.
    let env = environment(Some(&args.embree_config))?;
    if args.json {
        let text = serde_json::to_string_pretty(&env).map_err(anyhow::Error::from)?;
        outln!("{text}")?;
    } else {
        for (name, value) in env.rows() {
            outln!("{name:<12} {value}")?;
        }
        let linked: Vec<&str> = Engine::ALL
            .iter()
            .filter(|e| e.linked())
            .map(|e| e.name())
            .collect();
        outln!("{:<12} {}", "engines", linked.join(" "))?;
    }
    Ok(())
}
