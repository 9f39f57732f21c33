//! tetlab, the application: the command-line subcommands ([`cli`]), the interactive workbench
//! ([`gui`]) and Rerun recordings ([`record`]). The binary `tetlab` runs [`cli::main`], which
//! opens the workbench when no subcommand is given. The command line and recordings exist on the
//! desktop only; the workbench also compiles for `wasm32-unknown-unknown`, where `web.rs` starts
//! it on a web page.

#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
pub mod gui;
#[cfg(not(target_arch = "wasm32"))]
pub mod record;
#[cfg(target_arch = "wasm32")]
pub mod web;
