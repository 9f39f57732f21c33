//! `tetlab`: the workbench when started without a subcommand, otherwise the subcommand.

use std::process::ExitCode;

fn main() -> ExitCode {
    tetlab::cli::main()
}
