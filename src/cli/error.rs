//! How a subcommand fails: the error every subcommand returns, and the exit
//! code `cli::main` makes of it.

/// How a subcommand failed: the user's input (exit 2) or anything else (exit 1).
#[derive(Debug)]
pub enum CliError {
    /// Bad input: a malformed scene, an output path that cannot be written…
    BadInput(anyhow::Error),
    /// Any other failure.
    Failed(anyhow::Error),
    /// Stdout's reader is gone (`raypack … | head`): the command stops, and
    /// exits 0 saying nothing.
    StdoutClosed,
}

/// An output that cannot be written is the user's to fix (exit 2).
impl From<crate::atomic_file::OutputError> for CliError {
    fn from(e: crate::atomic_file::OutputError) -> Self {
        CliError::BadInput(e.into())
    }
}

impl From<anyhow::Error> for CliError {
    fn from(e: anyhow::Error) -> Self {
        CliError::Failed(e)
    }
}

/// Result of a subcommand.
pub type CliResult = Result<(), CliError>;
