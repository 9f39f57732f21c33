//! `tetlab`: on the desktop, the workbench when started without a subcommand, otherwise the
//! subcommand; in a browser, the workbench on the page's canvas.

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    tetlab::cli::main()
}

#[cfg(target_arch = "wasm32")]
fn main() {
    tetlab::web::start();
}
