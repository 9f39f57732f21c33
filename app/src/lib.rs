//! tetlab, the application: the command-line subcommands ([`cli`]) and the interactive workbench
//! ([`gui`]). The binary `tetlab` runs [`cli::main`], which opens the workbench when no subcommand
//! is given.

pub mod cli;
pub mod gui;
