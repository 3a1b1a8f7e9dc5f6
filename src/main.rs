//! The `raypack` binary; see `raypack --help`.

fn main() -> std::process::ExitCode {
    raypack::cli::main()
}
