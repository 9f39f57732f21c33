//! The workbench in a browser: started on the page's `<canvas id="tetlab">` (see `web/index.html`),
//! rendered by wgpu through WebGPU where the browser has it and WebGL2 otherwise (eframe chooses at
//! run time). The console says `tetlab ready` once the first frame is drawn.

use crate::gui::TetlabApp;
use crate::gui::platform::Platform;
use crate::gui::report::Report;
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
        // Before the workbench starts, so that a link to lesson 6 opens like any other.
        fetch_lesson_meshes().await;
        let started = eframe::WebRunner::new()
            .start(
                canvas,
                eframe::WebOptions {
                    wgpu_options: crate::gui::shared_device::wgpu_options(),
                    ..eframe::WebOptions::default()
                },
                Box::new(|cc| {
                    Ok(Box::new(TetlabApp::new(cc, Box::new(Page))?) as Box<dyn eframe::App>)
                }),
            )
            .await;
        if let Err(error) = started {
            log_error(&format!("tetlab could not start: {error:?}"));
        }
    });
}

/// Where the page looks for the meshes its lessons need: beside it, in `meshes/`, where
/// `scripts/web.sh` puts those of `../shared/meshes` when that folder is beside the repository.
pub const MESHES: &str = "meshes/";

/// Fetches the mesh files of the built-in lessons whose mesh is not built in (lesson 6's bunny,
/// a `.node` and its `.ele`) from [`MESHES`] and hands them to the library
/// ([`tetlab_core::input::text_file::provide`]), so that those lessons open as on the desktop. A file
/// the site does not have leaves its lesson greyed out in the picker, its note saying why.
async fn fetch_lesson_meshes() {
    let mut files: Vec<String> = Vec::new();
    for lesson in tetlab_core::teaching::lesson::BUILTIN {
        let Some(mesh) = lesson
            .header()
            .ok()
            .and_then(|h| h.missing_mesh().map(str::to_owned))
        else {
            continue;
        };
        let path = std::path::Path::new(&mesh);
        let needed = match path.extension().and_then(|e| e.to_str()) {
            Some("node" | "ele") => vec![path.with_extension("node"), path.with_extension("ele")],
            _ => vec![path.to_owned()],
        };
        for file in needed {
            if let Some(name) = file.file_name().and_then(|n| n.to_str())
                && !files.iter().any(|f| f == name)
            {
                files.push(name.to_owned());
            }
        }
    }
    for name in files {
        let url = format!("{MESHES}{name}");
        match fetch_text(&url).await {
            Ok(text) => {
                log(&format!("tetlab: fetched {url} ({} bytes)", text.len()));
                tetlab_core::input::text_file::provide(&name, text);
            }
            Err(why) => log(&format!("tetlab: {url} is not on this site ({why})")),
        }
    }
}

/// The text at `url`, or why not.
async fn fetch_text(url: &str) -> Result<String, String> {
    use wasm_bindgen_futures::JsFuture;
    let window = web_sys::window().ok_or("no window")?;
    let response = JsFuture::from(window.fetch_with_str(url))
        .await
        .map_err(|e| format!("{e:?}"))?
        .dyn_into::<web_sys::Response>()
        .map_err(|_| "not a response".to_owned())?;
    if !response.ok() {
        return Err(format!("HTTP {}", response.status()));
    }
    let text = response.text().map_err(|e| format!("{e:?}"))?;
    JsFuture::from(text)
        .await
        .map_err(|e| format!("{e:?}"))?
        .as_string()
        .ok_or_else(|| "not text".to_owned())
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

/// The page, as the workbench sees it ([`Platform`]).
struct Page;

impl Platform for Page {
    fn log(&self, line: &str) {
        log(line);
    }

    fn fragment(&self) -> String {
        fragment()
    }

    fn page_address(&self) -> String {
        page_address()
    }

    fn publishes(&self) -> bool {
        true
    }

    /// Keeps `report` for [`tetlab_state`].
    fn publish(&self, report: &Report) {
        let json = serde_json::to_string(report).unwrap_or_default();
        STATE.with(|state| *state.borrow_mut() = json);
    }
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
