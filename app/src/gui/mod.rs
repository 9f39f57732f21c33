//! The interactive workbench: an eframe app on wgpu. The 3D view is in [`viewport`] (drawing in
//! [`render`], what to draw in [`geometry`]), the state in [`workbench`], and each panel in a
//! file of its own under [`panels`], all with one signature: they draw and add [`request::Request`]s,
//! which the app (`app/frame.rs`) carries out in one loop once every panel is drawn.

pub mod app;
#[cfg(not(target_arch = "wasm32"))]
pub mod browser;
pub mod camera;
pub mod energy_watch;
pub mod files;
pub mod fonts;
pub mod geometry;
pub mod link;
pub mod panels;
pub mod platform;
pub mod preferences;
pub mod render;
pub mod report;
pub mod request;
pub mod shared_device;
pub mod shortcuts;
pub mod vertices;
pub mod viewport;
pub mod workbench;

pub use app::{CLASSROOM_ZOOM, Comparison, TetlabApp};
pub use fonts::install_fonts;
pub use preferences::Preferences;

#[cfg(not(target_arch = "wasm32"))]
use eframe::egui;
#[cfg(not(target_arch = "wasm32"))]
use platform::Desktop;

/// Opens the workbench window.
#[cfg(not(target_arch = "wasm32"))]
pub fn run_native() -> Result<(), String> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("tetlab")
            .with_inner_size([1280.0, 800.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: shared_device::wgpu_options(),
        ..Default::default()
    };
    eframe::run_native(
        "tetlab",
        options,
        Box::new(|cc| Ok(Box::new(TetlabApp::new(cc, Box::new(Desktop))?) as Box<dyn eframe::App>)),
    )
    .map_err(|e| e.to_string())
}
