//! One frame of the workbench: input and dropped files, a frame of simulation while playing,
//! the panels laid out (classroom mode or the full workbench), the 3D views, and the requests
//! the panels added carried out once every panel is drawn.

use super::super::files;
use super::super::panels::{Context, Panel};
use super::super::request::Request;
use super::super::shortcuts::{Action, SHORTCUTS};
use super::{CLASSROOM_ZOOM, TetlabApp};
use eframe::egui;
use web_time::Instant;

impl TetlabApp {
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
            #[cfg(not(target_arch = "wasm32"))]
            self.opened(files::open_dropped(file.as_ref()));
            #[cfg(target_arch = "wasm32")]
            files::open_dropped(file, &self.inbox);
        }
        #[cfg(target_arch = "wasm32")]
        for opened in self.inbox.take() {
            self.opened(opened);
        }
    }

    /// The "Open mesh file…" window, when open; opens what is chosen in it.
    #[cfg(not(target_arch = "wasm32"))]
    fn show_browser(&mut self, ctx: &egui::Context) {
        let Some(browser) = &mut self.browser else {
            return;
        };
        let mut open = true;
        let chosen = browser.show(ctx, &mut open);
        if !open {
            self.browser = None;
        }
        if let Some(path) = chosen {
            self.controls.scene.path = path.display().to_string();
            self.opened(files::open_path(&path.to_string_lossy()));
        }
    }

    /// Plays a frame of each simulation while playing, and counts down a lesson step's frames.
    /// A frame under way (the page's GPU engine, whose results come back between two of the
    /// page's frames) is carried on whether playing or not, and counts when it is done; its
    /// step time runs from its start to then.
    fn advance(&mut self, ctx: &egui::Context) {
        let under_way = self.bench.simulation.pending();
        if !self.bench.playing && !under_way {
            return;
        }
        if !under_way {
            self.frame_started = Instant::now();
        }
        let frame = self.bench.simulation.frame();
        self.bench.step_frame();
        // The right side starts a frame with the left one, and carries on one under way.
        if let Some(comparison) = &mut self.comparison
            && (comparison.bench.simulation.pending() || (comparison.bench.playing && !under_way))
        {
            comparison.bench.step_frame();
        }
        ctx.request_repaint();
        if self.bench.simulation.frame() == frame {
            return;
        }

        self.step_time = self.frame_started.elapsed();
        if self.bench.pause_if_slow(self.step_time) {
            self.set_playing(false);
        }
        if let Some(state) = &mut self.lesson
            && state.frames_left > 0
        {
            state.frames_left -= 1;
            if state.frames_left == 0 {
                self.set_playing(false);
            }
        }
    }

    /// A simulation that diverged (and went back to rest) is reported where errors are.
    fn show_divergence(&mut self) {
        let twin = self.comparison.as_mut().map(|c| &mut c.bench);
        for (bench, which) in [(Some(&mut self.bench), ""), (twin, "right: ")] {
            if let Some(divergence) = bench.and_then(|b| b.diverged.take()) {
                self.error = Some(format!("{which}{divergence}; back to the rest shape"));
            }
        }
    }

    /// The 3D view, or two side by side when comparing, each titled with its families.
    fn views(&mut self, ui: &mut egui::Ui) {
        let view = self.display.options;
        let Some(comparison) = &mut self.comparison else {
            self.viewport.show(ui, &mut self.bench, &self.cache, &view);
            return;
        };
        let size = if self.classroom { 20.0 } else { 14.0 };
        ui.columns(2, |columns| {
            let [left, right] = columns else {
                unreachable!("two columns")
            };
            for (ui, bench, viewport) in [
                (left, &mut self.bench, &mut self.viewport),
                (right, &mut comparison.bench, &mut comparison.viewport),
            ] {
                let families = (bench.simulation.families()).describe(bench.simulation.active());
                ui.add(
                    egui::Label::new(egui::RichText::new(families).size(size).strong()).truncate(),
                );
                viewport.show(ui, bench, &self.cache, &view);
            }
        });
    }
}

/// The top of the left panel: the name, the buttons that open what is not a side panel, and the
/// last error.
fn header(
    ui: &mut egui::Ui,
    error: Option<&str>,
    notice: Option<&str>,
    requests: &mut Vec<Request>,
) {
    ui.horizontal(|ui| {
        ui.heading("tetlab");
        for (label, action) in [
            ("Help (H)", Action::Help),
            ("Lessons (L)", Action::Lesson),
            ("Classroom (F5)", Action::Classroom),
        ] {
            if ui.button(label).clicked() {
                requests.push(Request::Act(action));
            }
        }
    });
    if let Some(error) = error {
        ui.colored_label(egui::Color32::from_rgb(220, 60, 60), error);
    }
    if let Some(notice) = notice {
        ui.small(notice);
    }
}

impl eframe::App for TetlabApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        let now = Instant::now();
        if let Some(last) = self.last_frame {
            // A running mean over about ten frames, so that the number can be read.
            let elapsed = now - last;
            self.frame_time = (self.frame_time * 9 + elapsed) / 10;
        }
        self.last_frame = Some(now);
        self.handle_input(&ctx);
        let zoom = if self.classroom { CLASSROOM_ZOOM } else { 1.0 };
        if ctx.zoom_factor() != zoom {
            ctx.set_zoom_factor(zoom);
        }
        self.advance(&ctx);
        self.show_divergence();
        let mut requests = Vec::new();
        let context = Context {
            bench: &self.bench,
            comparison: self.comparison.as_ref().map(|c| &c.bench),
            lesson: self.lesson.as_ref(),
            step_time: self.frozen_timings.map_or(self.step_time, |t| t.0),
            frame_time: self.frozen_timings.map_or(self.frame_time, |t| t.1),
            classroom: self.classroom,
        };
        if self.classroom {
            egui::Panel::right("classroom lesson")
                .default_size(ui.available_width() * 0.36)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        self.lesson_panel.ui(ui, &context, &mut requests);
                        ui.add_space(12.0);
                        ui.label(
                            "Left/Right: steps   Enter: do it   Space: play   F5: leave classroom",
                        );
                    });
                });
        } else {
            egui::Panel::left("controls")
                .default_size(300.0)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        header(
                            ui,
                            self.error.as_deref(),
                            self.notice.as_deref(),
                            &mut requests,
                        );
                        let panels: [&mut dyn Panel; 4] = [
                            &mut self.controls,
                            &mut self.solver,
                            &mut self.tools,
                            &mut self.compare,
                        ];
                        for (k, panel) in panels.into_iter().enumerate() {
                            if k > 0 {
                                ui.separator();
                            }
                            panel.ui(ui, &context, &mut requests);
                        }
                    });
                });
            egui::Panel::right("readouts")
                .default_size(300.0)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        self.readouts.ui(ui, &context, &mut requests);
                        ui.separator();
                        self.display.ui(ui, &context, &mut requests);
                    });
                });
            self.editor.ui(ui, &context, &mut requests);
            if self.show_lesson {
                egui::Panel::bottom("lesson")
                    .resizable(true)
                    .default_size(250.0)
                    .min_size(120.0)
                    .show(ui, |ui| {
                        egui::ScrollArea::vertical()
                            .auto_shrink([false, false])
                            .show(ui, |ui| {
                                ui.horizontal(|ui| {
                                    ui.heading("Lesson");
                                    if ui.button("Close (L)").clicked() {
                                        requests.push(Request::Act(Action::Lesson));
                                    }
                                });
                                self.lesson_panel.ui(ui, &context, &mut requests);
                            });
                    });
            }
            self.inspector.ui(ui, &context, &mut requests);
            self.modes.ui(ui, &context, &mut requests);
        }
        self.help.ui(ui, &context, &mut requests);
        egui::CentralPanel::default_margins().show(ui, |ui| self.views(ui));
        #[cfg(not(target_arch = "wasm32"))]
        self.show_browser(&ctx);
        for request in requests {
            self.apply(request);
        }
        if let Some(url) = self.link_to_copy.take() {
            ctx.copy_text(url);
        }
        self.frames_drawn += 1;
        // The first frame is painted before the second runs: ask for a second, and announce then.
        #[cfg(target_arch = "wasm32")]
        if self.frames_drawn == 1 {
            ctx.request_repaint();
        }
        // What a browser test reads (window.tetlab_state()).
        if self.platform.publishes() {
            self.platform.publish(&self.report());
        }
        if self.frames_drawn == 2 {
            self.platform.log(&format!(
                "tetlab ready: {} with {} tets drawn; SIMD lanes in {}",
                self.bench.scene.name,
                self.bench.simulation.tets().len(),
                tetlab_core::numbers::lanes::REGISTERS
            ));
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.preferences().save(storage);
    }
}
