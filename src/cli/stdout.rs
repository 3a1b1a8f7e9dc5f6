//! Results on stdout. A reader that stops early (`raypack … | head`) is not
//! the command's failure: the first write that finds the pipe closed ends the
//! command quietly, with exit code 0, as [`CliError::StdoutClosed`] ([`main`](super::main)
//! says nothing for it). Outputs already committed stay; a temporary output
//! not yet committed is removed when its writer drops. Any other write error
//! is a failure (exit 1).

use std::fmt;
use std::io::{self, Write};

use crate::cli::error::CliError;

/// What a failed write to stdout means for the command.
pub fn write_error(e: io::Error) -> CliError {
    if e.kind() == io::ErrorKind::BrokenPipe {
        CliError::StdoutClosed
    } else {
        CliError::Failed(anyhow::Error::from(e).context("cannot write to stdout"))
    }
}

/// Write `text` to stdout.
pub fn write_str(text: &str) -> Result<(), CliError> {
    io::stdout()
        .lock()
        .write_all(text.as_bytes())
        .map_err(write_error)
}

/// Write formatted text to stdout; what [`out!`] and [`outln!`] expand to.
pub fn write_fmt(args: fmt::Arguments<'_>) -> Result<(), CliError> {
    io::stdout().lock().write_fmt(args).map_err(write_error)
}

/// `print!` for results: evaluates to `Result<(), CliError>` (see the module).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::stdout::write_fmt(format_args!($($arg)*))
    };
}

/// `println!` for results: evaluates to `Result<(), CliError>` (see the module).
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::stdout::write_fmt(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {out, outln};
