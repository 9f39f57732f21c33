//! The workbench application: what it holds (one [`super::workbench::Workbench`] or two side by
//! side, the panels, the lesson, the link) and what each request the panels add does. One frame
//! drawn is `frame.rs`.

mod frame;

#[cfg(not(target_arch = "wasm32"))]
use super::browser;
use super::files::Opened;
use super::fonts::install_fonts;
use super::geometry::SceneCache;
use super::link::{Link, LinkScene};
use super::panels::compare::ComparePanel;
use super::panels::constraint_editor::ConstraintEditor;
use super::panels::controls::Controls;
use super::panels::display::DisplayPanel;
use super::panels::help::Help;
use super::panels::inspector::Inspector;
use super::panels::lesson::{LessonPanel, LessonState};
use super::panels::modes::ModesPanel;
use super::panels::readouts::Readouts;
use super::panels::solver::SolverPanel;
use super::panels::tools::Tools;
use super::platform::{Desktop, Platform};
use super::preferences::Preferences;
use super::request::Request;
use super::request::{LessonRequest, SceneRequest};
use super::shortcuts::Action;
use super::viewport::Viewport;
use super::workbench::Workbench;
use super::{files, render};
use std::time::Duration;
use tetlab_core::constraints::PerFamily;
use tetlab_core::scene::{Builtin, Perturbation, Scene, ShippedScene};
use tetlab_core::simulation::EngineChoice;
use tetlab_core::simulation::Settings;
use tetlab_core::teaching::lesson::{Action as LessonAction, Lesson};
use web_time::Instant;

/// The right half of a side-by-side comparison: the same scene with other constraint families.
pub struct Comparison {
    /// Its simulation and selection.
    pub bench: Workbench,
    /// Its view.
    pub viewport: Viewport,
}

/// The workbench application.
pub struct TetlabApp {
    /// The simulation and selection.
    pub bench: Workbench,
    cache: SceneCache,
    /// The 3D view.
    pub viewport: Viewport,
    /// The last error to show (a mesh that did not load, …).
    pub error: Option<String>,
    pub(crate) step_time: Duration,
    /// When the frame under way (or the last one) started.
    frame_started: Instant,
    /// The time between the last two frames drawn, smoothed.
    frame_time: Duration,
    /// When the last frame was drawn.
    last_frame: Option<Instant>,
    /// Timings shown instead of the measured ones ([`TetlabApp::freeze_timings`]).
    frozen_timings: Option<(Duration, Duration)>,
    /// Whether the lesson window is open.
    pub show_lesson: bool,
    /// The lesson in progress.
    pub lesson: Option<LessonState>,
    /// The second simulation shown beside the first, if any.
    pub comparison: Option<Comparison>,
    /// Classroom mode: large, the 3D view and the lesson only.
    pub classroom: bool,
    /// Playback, step by step and the scene.
    pub controls: Controls,
    /// The solver settings.
    pub solver: SolverPanel,
    /// Deformations and the selection.
    pub tools: Tools,
    /// Side by side with other families.
    pub compare: ComparePanel,
    /// The metrics, engine and timings.
    pub readouts: Readouts,
    /// What the views draw.
    pub display: DisplayPanel,
    /// The lesson picker and the current step.
    pub lesson_panel: LessonPanel,
    /// The constraint editor.
    pub editor: ConstraintEditor,
    /// The inspector window.
    pub inspector: Inspector,
    /// The modes window.
    pub modes: ModesPanel,
    /// The help window.
    pub help: Help,
    /// Frames drawn so far (the first one is announced in a browser).
    frames_drawn: u64,
    /// The built-in scene shown and its resolution, or the shipped scene file (`None` for a
    /// mesh file, a scene file of the user's or a lesson's scene): what a link names.
    scene_shown: Option<LinkScene>,
    /// The built-in lesson open (its number, from 1): what a link names.
    lesson_number: Option<usize>,
    /// A link just made, to copy to the clipboard on this frame.
    link_to_copy: Option<String>,
    /// The last thing done that is worth a line (a link copied); not an error.
    pub notice: Option<String>,
    /// Dropped files read in the background.
    #[cfg(target_arch = "wasm32")]
    inbox: files::Inbox,
    /// "Open mesh file…" while it is open.
    #[cfg(not(target_arch = "wasm32"))]
    browser: Option<browser::FileBrowser>,
    /// Where it runs: a desktop window or a page.
    platform: Box<dyn Platform>,
}

/// How much larger everything is in classroom mode.
pub const CLASSROOM_ZOOM: f32 = 1.5;

impl TetlabApp {
    /// Sets up the renderer and restores the last session's preferences (or, when the page was
    /// opened by a link, the link's state), for `platform`.
    pub fn new(
        cc: &eframe::CreationContext<'_>,
        platform: Box<dyn Platform>,
    ) -> Result<Self, String> {
        let render_state = cc
            .wgpu_render_state
            .as_ref()
            .ok_or("tetlab's 3D view needs the wgpu renderer")?;
        render::Renderer::install(render_state);
        platform.log(&format!(
            "tetlab: drawing with {:?}",
            render_state.adapter.get_info().backend
        ));
        // Before anything asks whether the GPU engine can run.
        platform.log(&super::shared_device::share_with_the_engine(render_state));
        install_fonts(&cc.egui_ctx);
        let preferences = cc.storage.map(Preferences::load).unwrap_or_default();
        // A page opened by a link shows the link's state, from the defaults.
        let fragment = platform.fragment();
        if !fragment.trim_start_matches('#').is_empty() {
            let mut app = TetlabApp::with_preferences(Preferences::default());
            app.open_fragment(&fragment);
            match &app.error {
                Some(error) => platform.log(&format!("tetlab: link not opened: {error}")),
                None => platform.log("tetlab: link opened"),
            }
            if let Some(notice) = &app.notice {
                platform.log(&format!("tetlab: {notice}"));
            }
            app.platform = platform;
            return Ok(app);
        }
        let mut app = TetlabApp::with_preferences(preferences);
        app.platform = platform;
        Ok(app)
    }

    /// The workbench on the scene and settings of `preferences` (the renderer must be installed).
    /// Settings that are out of range (remembered settings come from a file on disk, which may
    /// be old or edited by hand) are replaced by the defaults, and the error says so.
    pub fn with_preferences(mut preferences: Preferences) -> Self {
        let refused = preferences.settings.check().err();
        if refused.is_some() {
            preferences.settings = Preferences::default().settings;
        }
        let builtin = Builtin::from_name(&preferences.scene.builtin).unwrap_or(Builtin::Cube);
        let bench = Workbench::builtin(builtin, preferences.scene.resolution, preferences.settings);
        let shown_resolution = preferences.scene.resolution.clamp(1, 16);
        let cache = SceneCache::new(&bench.scene.mesh);
        let viewport = Viewport::default();
        TetlabApp {
            bench,
            cache,
            viewport,
            error: refused.map(|why| {
                format!("the remembered solver settings were refused ({why}); using the defaults")
            }),
            step_time: Duration::ZERO,
            frame_started: Instant::now(),
            frame_time: Duration::ZERO,
            last_frame: None,
            frozen_timings: None,
            show_lesson: false,
            lesson: None,
            comparison: None,
            classroom: false,
            controls: Controls {
                scene: preferences.scene,
            },
            solver: SolverPanel,
            tools: Tools,
            compare: ComparePanel::default(),
            readouts: Readouts,
            display: DisplayPanel {
                options: preferences.view,
            },
            lesson_panel: LessonPanel::default(),
            editor: ConstraintEditor::default(),
            inspector: Inspector::default(),
            modes: ModesPanel::default(),
            help: Help::default(),
            frames_drawn: 0,
            scene_shown: Some(LinkScene::Builtin(builtin, shown_resolution)),
            lesson_number: None,
            link_to_copy: None,
            notice: None,
            #[cfg(target_arch = "wasm32")]
            inbox: files::Inbox::default(),
            #[cfg(not(target_arch = "wasm32"))]
            browser: None,
            platform: Box::new(Desktop),
        }
    }

    /// Shows these step and frame times in the readouts instead of the measured ones: for
    /// screenless tests, whose snapshots must not depend on how fast the machine is.
    pub fn freeze_timings(&mut self, step: Duration, frame: Duration) {
        self.frozen_timings = Some((step, frame));
    }

    /// What the workbench remembers between runs: the scene section, the solver settings and
    /// the display options, as they are now.
    pub fn preferences(&self) -> Preferences {
        Preferences {
            scene: self.controls.scene.clone(),
            settings: *self.bench.simulation.settings(),
            view: self.display.options,
        }
    }

    /// Replaces the scene; keeps settings and view (but particle handles and arrows, which
    /// [`super::geometry::ViewOptions::fit_size`] sets for the scene's size); ends a comparison.
    pub fn load(&mut self, scene: Scene) {
        self.bench.load(scene);
        self.cache = SceneCache::new(&self.bench.scene.mesh);
        // A big mesh is shown as a body: its particle handles and arrows start off.
        let tets = self.bench.simulation.tets().len();
        self.display.options.fit_size(tets);
        self.viewport.frame();
        self.comparison = None;
        self.error = None;
        self.scene_shown = None;
    }

    /// Opens a lesson at its first step: its scene, settings and tet. A lesson that brings
    /// constraint files puts the first in the editor, where its exercise is done.
    pub fn open_lesson(&mut self, lesson: Lesson) {
        self.lesson_number = None;
        if let Some(&family) = lesson.file_families.first()
            && let Some(file) = lesson.families.file(family)
        {
            self.editor.set_text(&file.path, &file.source);
            self.editor.family = Some(family);
            self.editor.families = vec![family];
        } else {
            // The lesson's table replaces the workbench's: what the editor defined is not in it.
            self.editor.family = None;
            self.editor.families.clear();
            self.editor.report = None;
        }
        self.load(lesson.scene());
        self.bench.set_families(lesson.families.clone());
        self.bench.set_settings(lesson.settings);
        self.bench.select_tet(lesson.tet);
        self.viewport.reset_camera();
        self.lesson = Some(LessonState {
            lesson,
            step: 0,
            frames_left: 0,
        });
        self.show_lesson = true;
    }

    /// Does the current lesson step: its actions (on both simulations when comparing), then
    /// plays its frames.
    pub fn do_step(&mut self) {
        let Some(step) = self.lesson.as_ref().map(|state| state.current().clone()) else {
            return;
        };
        for action in step.actions {
            match action {
                LessonAction::Compare(families) => self.compare(families),
                action => {
                    self.bench.apply_lesson_action(action);
                    if let Some(comparison) = &mut self.comparison
                        && action.applies_to_comparison()
                    {
                        comparison.bench.apply_lesson_action(action);
                    }
                }
            }
        }
        if let Some(state) = &mut self.lesson {
            state.frames_left = step.frames;
        }
        if step.frames > 0 {
            self.set_playing(true);
        }
    }

    /// Changes the solver settings of the simulation, and of the comparison beside it (as a
    /// lesson's actions do): everything but its own families.
    pub fn set_settings(&mut self, settings: Settings) {
        self.bench.set_settings(settings);
        if let Some(comparison) = &mut self.comparison {
            let active = *comparison.bench.simulation.active();
            comparison
                .bench
                .set_settings(Settings { active, ..settings });
        }
    }

    /// Starts comparing side by side with a twin of the current state using `families`, or
    /// stops (`None`).
    pub fn compare(&mut self, families: Option<PerFamily<bool>>) {
        self.comparison = families.map(|active| {
            let bench = self.bench.twin(active);
            let mut viewport = Viewport::default();
            viewport.view = 1;
            viewport.camera = self.viewport.camera;
            viewport.frame();
            Comparison { bench, viewport }
        });
        // The main view changes width: frame it once laid out.
        self.viewport.frame();
    }

    /// Opens "Open mesh file…" in the folder of the last file, or the current folder.
    fn open_browser(&mut self) {
        #[cfg(not(target_arch = "wasm32"))]
        {
            let last = std::path::Path::new(&self.controls.scene.path);
            let folder = last
                .parent()
                .filter(|p| p.is_dir())
                .map(std::path::Path::to_path_buf)
                .unwrap_or_else(|| std::path::PathBuf::from("."));
            self.browser = Some(browser::FileBrowser::new(&folder));
        }
    }

    fn go_to_step(&mut self, forward: bool) {
        if let Some(state) = &mut self.lesson {
            let last = state.lesson.steps.len() - 1;
            state.step = if forward {
                (state.step + 1).min(last)
            } else {
                state.step.saturating_sub(1)
            };
            state.frames_left = 0;
        }
    }

    fn set_playing(&mut self, playing: bool) {
        self.bench.set_playing(playing);
        if let Some(comparison) = &mut self.comparison {
            comparison.bench.set_playing(playing);
        }
    }

    fn request(&mut self, request: SceneRequest) {
        match request {
            SceneRequest::Builtin(builtin, resolution) => {
                if let Err(why) = self.load_builtin(builtin, resolution) {
                    self.error = Some(why);
                }
            }
            SceneRequest::File(path) => self.opened(files::open_path(&path)),
            SceneRequest::AddBody(builtin, resolution) => {
                if let Err(why) = self.add_body(builtin, resolution) {
                    self.error = Some(why);
                }
            }
            SceneRequest::Shipped(file) => {
                if let Err(why) = self.load_shipped(file) {
                    self.error = Some(why);
                }
            }
        }
    }

    /// Adds a built-in to the scene shown as one more body, dropped onto it from above
    /// ([`Scene::with_body_dropped`]); the scene starts again with it, under the same settings.
    /// Too many tets for tetlab is an error, and the scene stays.
    pub fn add_body(&mut self, builtin: Builtin, resolution: u32) -> Result<(), String> {
        let part = Scene::builtin(builtin, resolution).map_err(|e| e.to_string())?;
        let tets = self.bench.scene.mesh.tets.len() + part.mesh.tets.len();
        if tets > tetlab_core::input::limits::MAX_TETS {
            return Err(format!(
                "Add a body: the scene would have {tets} tets, more than the {} tetlab simulates",
                tetlab_core::input::limits::MAX_TETS
            ));
        }
        let scene = self.bench.scene.with_body_dropped(part);
        self.load(scene);
        Ok(())
    }

    /// Loads a scene file that comes with tetlab ([`ShippedScene`]), which a link can then
    /// name; an error (a mesh file it needs is not there, as in the browser) names it.
    pub fn load_shipped(&mut self, file: &str) -> Result<(), String> {
        let shipped = ShippedScene::named(file)
            .ok_or_else(|| format!("{file}: not a scene file that comes with tetlab"))?;
        let scene = shipped
            .scene()
            .map_err(|e| format!("{}: {e}", shipped.file))?;
        self.load(scene);
        self.scene_shown = Some(LinkScene::Shipped(shipped.file));
        Ok(())
    }

    /// Loads a built-in scene ([`TetlabApp::load`]), which a link can then name.
    pub fn load_builtin(&mut self, builtin: Builtin, resolution: u32) -> Result<(), String> {
        let scene = Scene::builtin(builtin, resolution).map_err(|e| e.to_string())?;
        self.load(scene);
        self.scene_shown = Some(LinkScene::Builtin(builtin, resolution));
        Ok(())
    }

    /// A link to the state shown: the built-in scene, the settings, the lesson and its step, the
    /// camera, and the edits made since the scene was loaded.
    pub fn link(&self) -> Link {
        Link {
            scene: self.scene_shown,
            settings: *self.bench.simulation.settings(),
            lesson: self
                .lesson_number
                .zip(self.lesson.as_ref().map(|state| state.step)),
            camera: Some(self.viewport.camera),
            edits: self.bench.edits.clone(),
        }
    }

    /// Shows the state a link describes: its lesson at its step (or its scene), its settings,
    /// its edits made again, its camera. An edit that does not fit is reported and the rest
    /// left out.
    pub fn open_link(&mut self, link: Link) {
        if let Some((number, step)) = link.lesson {
            self.lesson_request(LessonRequest::Builtin(number));
            self.show_lesson = true;
            for _ in 0..step {
                self.go_to_step(true);
            }
        } else {
            match link.scene {
                Some(LinkScene::Builtin(builtin, resolution)) => {
                    self.controls.scene.builtin = builtin.name().to_owned();
                    self.controls.scene.resolution = resolution;
                    self.request(SceneRequest::Builtin(builtin, resolution));
                }
                Some(LinkScene::Shipped(file)) => {
                    self.controls.scene.shipped = file.to_owned();
                    self.request(SceneRequest::Shipped(file));
                }
                None => {}
            }
        }
        let mut settings = link.settings;
        if let Err(why) = settings.engine.available() {
            // A link made where the GPU engine runs, opened where it cannot.
            self.notice = Some(format!(
                "the link's engine '{}' cannot run here ({why}): the CPU engines run instead",
                settings.engine.name()
            ));
            settings.engine = EngineChoice::Auto;
        }
        self.set_settings(settings);
        for edit in link.edits {
            if let Err(why) = self.bench.apply_edit(edit) {
                self.error = Some(format!("the link's edits: {why}; the later ones left out"));
                break;
            }
        }
        if let Some(camera) = link.camera {
            self.viewport.camera = camera;
        }
    }

    /// Opens the state of a URL fragment; a fragment that cannot be read leaves the workbench
    /// as it is, and says why.
    pub fn open_fragment(&mut self, fragment: &str) {
        match Link::parse(fragment) {
            Ok(link) => self.open_link(link),
            Err(error) => {
                self.error = Some(format!("{error}; the workbench opened with its defaults"))
            }
        }
    }

    /// The whole link to the state shown: the page's address (in a browser, this page's;
    /// on the desktop, [`super::link::page_url`]) and the fragment.
    pub fn link_url(&self) -> String {
        let page = self.platform.page_address();
        format!("{page}#{}", self.link().fragment())
    }

    fn opened(&mut self, opened: Result<Opened, String>) {
        match opened {
            Ok(Opened::Scene(scene)) => self.load(scene),
            Ok(Opened::Lesson(lesson)) => self.open_lesson(*lesson),
            Ok(Opened::Constraint { path, text }) => {
                self.editor.open = true;
                self.error = None;
                match self.editor.set_text(&path, &text) {
                    Some(files) => self.define_constraints(files),
                    None => self.error = self.editor.error.clone(),
                }
            }
            Err(message) => self.error = Some(message),
        }
    }

    /// Defines the family of a constraint file the editor compiled (replacing the one of the
    /// same name), switches it on (and the editor's previous family off, when the name
    /// changed), and rebuilds its constraints in every simulation shown.
    pub fn define_constraint(&mut self, file: tetlab_core::constraint_file::ConstraintFile) {
        self.define_constraints(vec![file]);
    }

    /// [`TetlabApp::define_constraint`] for every constraint of a file (one per
    /// `[[constraint]]`): each is defined and switched on, and those of the editor's previous
    /// text that this one does not define are switched off.
    pub fn define_constraints(&mut self, files: Vec<tetlab_core::constraint_file::ConstraintFile>) {
        let mut families = self.bench.simulation.families().clone();
        let defined = match families.define_all(files) {
            Ok(defined) => defined,
            Err(message) => {
                self.editor.error = Some(format!("{}: {message}", self.editor.path.display()));
                return;
            }
        };
        let previous = std::mem::replace(&mut self.editor.families, defined.clone());
        self.editor.family = defined.first().copied();
        let mut settings = *self.bench.simulation.settings();
        for &family in &defined {
            if !previous.contains(&family) {
                settings.active[family] = true;
            }
        }
        for family in previous {
            if !defined.contains(&family) {
                settings.active[family] = false;
            }
        }
        if let Some(comparison) = &mut self.comparison {
            comparison.bench.set_families(families.clone());
        }
        self.bench.set_families(families);
        self.set_settings(settings);
    }

    fn lesson_request(&mut self, request: LessonRequest) {
        match request {
            LessonRequest::Builtin(k) => match Lesson::builtin(k) {
                Ok(lesson) => {
                    self.open_lesson(lesson);
                    self.lesson_number = Some(k);
                }
                Err(e) => self.error = Some(e.to_string()),
            },
            LessonRequest::File(path) => self.opened(files::open_path(&path)),
            LessonRequest::Do => self.do_step(),
            LessonRequest::Next => self.go_to_step(true),
            LessonRequest::Previous => self.go_to_step(false),
        }
    }

    /// Carries out what a panel asked for.
    pub fn apply(&mut self, request: Request) {
        match request {
            Request::Act(action) => self.act(action),
            Request::Scene(request) => self.request(request),
            Request::Lesson(request) => self.lesson_request(request),
            Request::Compare(families) => self.compare(families),
            Request::Settings(settings) => self.set_settings(*settings),
            Request::Constraint(files) => self.define_constraints(files),
            Request::ShowMode(mode) => self.bench.mode_shown = mode,
            Request::ExactStep(on) => self.bench.exact_step = on,
        }
    }

    /// Does what a key or a button asks; actions on the simulation go to both halves of a
    /// comparison.
    pub fn act(&mut self, action: Action) {
        match action {
            Action::FrameView => self.viewport.frame(),
            Action::ResetCamera => self.viewport.reset_camera(),
            Action::CopyLink => {
                let url = self.link_url();
                // On the desktop the link is printed too, for a terminal or a script.
                #[cfg(not(target_arch = "wasm32"))]
                println!("{url}");
                self.notice = Some(format!("link copied ({} characters)", url.len()));
                self.link_to_copy = Some(url);
            }
            Action::Inspector => self.inspector.open = !self.inspector.open,
            Action::Modes => self.modes.open = !self.modes.open,
            Action::Help => self.help.open = !self.help.open,
            Action::Lesson => self.show_lesson = !self.show_lesson,
            Action::ConstraintEditor => {
                self.editor.open = !self.editor.open;
                if self.editor.open && self.editor.text.is_empty() {
                    let example = tetlab_core::constraint_file::EXAMPLES
                        .iter()
                        .find(|e| e.file == "height.toml")
                        .unwrap_or(&tetlab_core::constraint_file::EXAMPLES[0]);
                    if let Some(files) = self.editor.set_text(&example.shown(), example.text) {
                        self.define_constraints(files);
                    }
                }
            }
            Action::OpenFile => self.open_browser(),
            Action::Classroom => {
                self.classroom = !self.classroom;
                self.viewport.frame();
                if let Some(comparison) = &mut self.comparison {
                    comparison.viewport.frame();
                }
            }
            Action::NextStep => self.go_to_step(true),
            Action::PreviousStep => self.go_to_step(false),
            Action::DoStep => self.do_step(),
            Action::PlayPause => self.set_playing(!self.bench.playing),
            simulation => {
                act_on(&mut self.bench, simulation);
                if let Some(comparison) = &mut self.comparison {
                    comparison.bench.selected_particle = self.bench.selected_particle;
                    comparison.bench.selected_tet = self.bench.selected_tet;
                    act_on(&mut comparison.bench, simulation);
                }
            }
        }
    }
}

/// Does a simulation action on one workbench.
fn act_on(bench: &mut Workbench, action: Action) {
    match action {
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
        _ => {}
    }
}

#[cfg(test)]
mod tests;
