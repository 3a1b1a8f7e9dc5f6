//! A reader that stops early (`raypack … | head`) is not the command's
//! failure: every subcommand that prints results exits 0 without a word when
//! its stdout is a pipe nobody reads, never panics.

use std::process::{Command, Stdio};

use crate::support::cli::{SMALL_SCENE, stderr};

#[test]
fn a_closed_stdout_ends_each_command_quietly() {
    let commands: [&[&str]; 7] = [
        &["env"],
        &["env", "--json"],
        &["info", SMALL_SCENE],
        &["stats", "--spd", SMALL_SCENE],
        &["gen", "tetra", "--size", "3"],
        &[
            "bench",
            "kernels",
            "--rays",
            "64",
            "--rounds",
            "1",
            "--sample-ms",
            "1",
        ],
        &[
            "bench",
            "scene",
            SMALL_SCENE,
            "--size",
            "8x8",
            "--runs",
            "1",
            "--threads",
            "1",
            "--json",
        ],
    ];
    for args in commands {
        // The pipe's read end is closed before the command starts, so its
        // first write to stdout fails, whenever that comes.
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let out = Command::new(env!("CARGO_BIN_EXE_raypack"))
            .args(args)
            .stdout(writer)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let err = stderr(&out);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(out.status.success(), "{args:?}: {:?} {err}", out.status);
    }
}
