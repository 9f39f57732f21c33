//! The workbench in a browser: started on the page's `<canvas id="tetlab">` (see `web/index.html`),
//! rendered by wgpu through WebGPU where the browser has it and WebGL2 otherwise (eframe chooses at
//! run time). The console says `tetlab ready` once the first frame is drawn.

use crate::gui::TetlabApp;
use wasm_bindgen::JsCast;

/// The id of the canvas the workbench draws on.
pub const CANVAS_ID: &str = "tetlab";

/// Starts the workbench on the page; errors go to the browser console.
pub fn start() {
    wasm_bindgen_futures::spawn_local(async {
        let canvas = web_sys::window()
            .and_then(|w| w.document())
            .and_then(|d| d.get_element_by_id(CANVAS_ID))
            .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok());
        let Some(canvas) = canvas else {
            log_error(&format!(
                "tetlab: the page has no <canvas id=\"{CANVAS_ID}\">"
            ));
            return;
        };
        let started = eframe::WebRunner::new()
            .start(
                canvas,
                eframe::WebOptions::default(),
                Box::new(|cc| Ok(Box::new(TetlabApp::new(cc)?) as Box<dyn eframe::App>)),
            )
            .await;
        if let Err(error) = started {
            log_error(&format!("tetlab could not start: {error:?}"));
        }
    });
}

/// The page's URL fragment (`#…`, or empty): a link to a state ([`crate::gui::link`]).
pub fn fragment() -> String {
    web_sys::window()
        .and_then(|w| w.location().hash().ok())
        .unwrap_or_default()
}

/// The page's address without its fragment: what a link to a state starts with.
pub fn page_address() -> String {
    let href = web_sys::window()
        .and_then(|w| w.location().href().ok())
        .unwrap_or_default();
    href.split('#').next().unwrap_or_default().to_owned()
}

thread_local! {
    /// The workbench's state after its last frame, as JSON.
    static STATE: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

/// Keeps `report` for [`tetlab_state`].
pub fn publish(report: &crate::gui::report::Report) {
    let json = serde_json::to_string(report).unwrap_or_default();
    STATE.with(|state| *state.borrow_mut() = json);
}

/// The workbench's state after its last frame, as JSON ([`crate::gui::report::Report`]); empty
/// before the first frame. `web/index.html` makes it `window.tetlab_state()`, for tests.
#[wasm_bindgen::prelude::wasm_bindgen]
pub fn tetlab_state() -> String {
    STATE.with(|state| state.borrow().clone())
}

/// Writes a line to the browser console.
pub fn log(line: &str) {
    web_sys::console::log_1(&line.into());
}

fn log_error(line: &str) {
    web_sys::console::error_1(&line.into());
}
