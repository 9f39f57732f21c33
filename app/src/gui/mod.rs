//! The interactive workbench: an eframe app on wgpu. The 3D view is in [`viewport`] (drawing in
//! [`render`], what to draw in [`geometry`]), the state in [`workbench`], and each side panel in a
//! file of its own under [`panels`].

pub mod camera;
pub mod files;
pub mod geometry;
pub mod panels;
pub mod render;
pub mod shortcuts;
pub mod viewport;
pub mod workbench;

use eframe::egui;
use geometry::{SceneCache, ViewOptions};
use panels::controls::{SceneChoice, SceneRequest};
use shortcuts::{Action, SHORTCUTS};
use std::time::Duration;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::solver::Settings;
use viewport::Viewport;
use web_time::Instant;
use workbench::Workbench;

/// What the workbench remembers between runs (eframe storage).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Preferences {
    /// The scene section.
    pub scene: SceneChoice,
    /// The solver settings.
    pub settings: Settings,
    /// The display options.
    pub view: ViewOptions,
}

impl Default for Preferences {
    /// The solver's defaults, except that edits settle: inverting or dragging by hand is undone
    /// without launching the body out of view.
    fn default() -> Self {
        Self {
            scene: SceneChoice::default(),
            settings: Settings {
                settle_edits: true,
                ..Settings::default()
            },
            view: ViewOptions::default(),
        }
    }
}

const STORAGE_KEY: &str = "tetlab";

/// Adds DejaVu Sans Mono after egui's own fonts, for the glyphs of the formulas (∇ ₀ ⅙ × λ Δ …)
/// that egui's fonts lack.
pub fn install_fonts(ctx: &egui::Context) {
    let mut fonts = egui::FontDefinitions::default();
    fonts.font_data.insert(
        "DejaVuSansMono".into(),
        std::sync::Arc::new(egui::FontData::from_static(include_bytes!(
            "../../../assets/fonts/DejaVuSansMono.ttf"
        ))),
    );
    for family in [egui::FontFamily::Proportional, egui::FontFamily::Monospace] {
        fonts
            .families
            .entry(family)
            .or_default()
            .push("DejaVuSansMono".into());
    }
    ctx.set_fonts(fonts);
}

/// The workbench application.
pub struct TetlabApp {
    /// The simulation and selection.
    pub bench: Workbench,
    cache: SceneCache,
    /// The 3D view.
    pub viewport: Viewport,
    /// What is remembered between runs.
    pub preferences: Preferences,
    /// The last error to show (a mesh that did not load, …).
    pub error: Option<String>,
    step_time: Duration,
    show_help: bool,
    /// Whether the inspector window is open.
    pub show_inspector: bool,
}

impl TetlabApp {
    /// Sets up the renderer and restores the last session's preferences.
    pub fn new(cc: &eframe::CreationContext<'_>) -> Result<Self, String> {
        let render_state = cc
            .wgpu_render_state
            .as_ref()
            .ok_or("tetlab's 3D view needs the wgpu renderer")?;
        render::Renderer::install(render_state);
        install_fonts(&cc.egui_ctx);
        let preferences: Preferences = cc
            .storage
            .and_then(|s| eframe::get_value(s, STORAGE_KEY))
            .unwrap_or_default();
        Ok(TetlabApp::with_preferences(preferences))
    }

    /// The workbench on the scene and settings of `preferences` (the renderer must be installed).
    pub fn with_preferences(preferences: Preferences) -> Self {
        let builtin = Builtin::from_name(&preferences.scene.builtin).unwrap_or(Builtin::Cube);
        let bench = Workbench::builtin(builtin, preferences.scene.resolution, preferences.settings);
        let cache = SceneCache::new(&bench.scene.mesh);
        let viewport = Viewport::new(&bench);
        TetlabApp {
            bench,
            cache,
            viewport,
            preferences,
            error: None,
            step_time: Duration::ZERO,
            show_help: false,
            show_inspector: false,
        }
    }

    /// Replaces the scene; keeps settings and view.
    pub fn load(&mut self, scene: Scene) {
        self.bench.load(scene);
        self.cache = SceneCache::new(&self.bench.scene.mesh);
        self.viewport.frame(&self.bench);
        self.error = None;
    }

    fn request(&mut self, request: SceneRequest) {
        let scene = match request {
            SceneRequest::Builtin(builtin, resolution) => {
                Scene::builtin(builtin, resolution).map_err(|e| e.to_string())
            }
            SceneRequest::File(path) => files::load_path(&path),
        };
        match scene {
            Ok(scene) => self.load(scene),
            Err(message) => self.error = Some(message),
        }
    }

    fn act(&mut self, action: Action) {
        let bench = &mut self.bench;
        match action {
            Action::PlayPause => bench.set_playing(!bench.playing),
            Action::StepFrame => bench.step_frame(),
            Action::StepSubstep => bench.step_substep(),
            Action::StepProjection => bench.step_projection(),
            Action::FinishSubstep => bench.finish_substep(),
            Action::Reset => bench.reset(),
            Action::InvertSelected => bench.invert_selected(),
            Action::Mirror => bench.perturb(Perturbation::Mirror),
            Action::Flatten => bench.perturb(Perturbation::Flatten),
            Action::Scramble => bench.scramble(),
            Action::TogglePin => bench.toggle_pin(),
            Action::NextTet => bench.next_tet_of_selected(),
            Action::FrameView => self.viewport.frame(&self.bench),
            Action::ResetCamera => self.viewport.reset_camera(&self.bench),
            Action::Inspector => self.show_inspector = !self.show_inspector,
            Action::Help => self.show_help = !self.show_help,
        }
    }

    fn handle_input(&mut self, ctx: &egui::Context) {
        if !ctx.egui_wants_keyboard_input() {
            let pressed: Vec<Action> = ctx.input(|i| {
                SHORTCUTS
                    .iter()
                    .filter(|(key, _, _)| i.key_pressed(*key))
                    .map(|(_, action, _)| *action)
                    .collect()
            });
            for action in pressed {
                self.act(action);
            }
        }
        let dropped = ctx.input(|i| i.raw.dropped_files.clone());
        for file in dropped {
            match files::load_dropped(file.as_ref()) {
                Ok(scene) => self.load(scene),
                Err(message) => self.error = Some(message),
            }
        }
    }
}

impl eframe::App for TetlabApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.handle_input(&ctx);
        if self.bench.playing {
            let started = Instant::now();
            self.bench.step_frame();
            self.step_time = started.elapsed();
            ctx.request_repaint();
        }
        let mut request = None;
        let mut view_request = None;
        egui::Panel::left("controls")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    ui.horizontal(|ui| {
                        ui.heading("tetlab");
                        if ui.button("Help (H)").clicked() {
                            self.show_help = !self.show_help;
                        }
                    });
                    if let Some(error) = &self.error {
                        ui.colored_label(egui::Color32::from_rgb(220, 60, 60), error);
                    }
                    request =
                        panels::controls::show(ui, &mut self.bench, &mut self.preferences.scene);
                    ui.separator();
                    panels::tools::show(ui, &mut self.bench, &mut self.show_inspector);
                });
            });
        egui::Panel::right("readouts")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    panels::readouts::show(ui, &self.bench, self.step_time);
                    ui.separator();
                    view_request = panels::display::show(
                        ui,
                        &mut self.preferences.view,
                        self.bench.simulation.tets().len(),
                    );
                });
            });
        egui::CentralPanel::default_margins().show(ui, |ui| {
            self.viewport
                .show(ui, &mut self.bench, &self.cache, &self.preferences.view);
        });
        panels::help::show(&ctx, &mut self.show_help);
        panels::inspector::show(&ctx, &mut self.show_inspector, &self.bench);
        if let Some(request) = request {
            self.request(request);
        }
        if let Some(action) = view_request {
            self.act(action);
        }
        self.preferences.settings = *self.bench.simulation.settings();
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, STORAGE_KEY, &self.preferences);
    }
}

/// Opens the workbench window.
#[cfg(not(target_arch = "wasm32"))]
pub fn run_native() -> Result<(), String> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("tetlab")
            .with_inner_size([1280.0, 800.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    eframe::run_native(
        "tetlab",
        options,
        Box::new(|cc| Ok(Box::new(TetlabApp::new(cc)?) as Box<dyn eframe::App>)),
    )
    .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use tetlab_core::solver::Method;

    /// What `save` writes, `new` reads back: eframe stores the preferences as RON text.
    #[test]
    fn preferences_survive_a_save_and_load() {
        let mut preferences = Preferences::default();
        preferences.scene.builtin = "ball".into();
        preferences.scene.resolution = 2;
        preferences.settings.method = Method::Pbd;
        preferences.settings.active.plane = true;
        preferences.settings.substeps = 7;
        preferences.view.see_through = true;
        let text = ron::to_string(&preferences).unwrap();
        let restored: Preferences = ron::from_str(&text).unwrap();
        assert_eq!(restored, preferences);
        let app = TetlabApp::with_preferences(restored);
        assert_eq!(app.bench.scene.name, "ball");
        assert_eq!(*app.bench.simulation.settings(), preferences.settings);
    }

    #[test]
    fn missing_or_old_preferences_fall_back_to_defaults() {
        let restored: Preferences = ron::from_str("(scene: (builtin: \"tet\"))").unwrap();
        assert_eq!(restored.scene.builtin, "tet");
        assert_eq!(restored.settings, Preferences::default().settings);
        assert!(restored.settings.settle_edits);
    }
}
