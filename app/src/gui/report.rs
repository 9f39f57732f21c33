//! What the workbench shows, as data: the scene, the inverted tets, whether it plays, the error,
//! the lesson step and its checks, and where the selected particle and its opposite face are on
//! the screen. A browser test reads it (`window.tetlab_state()`, `web/index.html`) to drive the
//! page as a user would and check what happened, without reading pixels.

use super::TetlabApp;
use super::viewport;
use glam::DVec3;
use serde::Serialize;
use tetlab_core::energy::modes::Modes;

/// The workbench's state, as [`TetlabApp::report`] gives it.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// The scene's name.
    pub scene: String,
    /// Its tets.
    pub tets: usize,
    /// How many are inverted.
    pub inverted_tets: usize,
    /// Frames simulated since the scene was loaded or reset.
    pub frame: u64,
    /// Whether the simulation plays.
    pub playing: bool,
    /// The error shown, if any.
    pub error: Option<String>,
    /// The notice shown, if any (a link's engine that cannot run here, and what runs instead).
    pub notice: Option<String>,
    /// The lesson open, if any.
    pub lesson: Option<LessonReport>,
    /// The selected tet's selected corner and the centre of its opposite face, in the page's
    /// (CSS) pixels, where both are in front of the camera.
    pub drag: Option<DragReport>,
    /// While the Modes window is open: what it shows of the selected tet's energy.
    pub modes: Option<ModesReport>,
    /// How this build holds the fast engine's lanes ([`tetlab_core::numbers::lanes::REGISTERS`]):
    /// WebAssembly SIMD registers, or arrays in the page's build without SIMD.
    pub lanes: &'static str,
    /// How long the last simulation step took, in milliseconds.
    pub step_ms: f64,
    /// The engine that steps the simulation ("reference (f64)", "fast (f32, 1 thread)").
    pub engine: String,
    /// The contact pairs touching ([`tetlab_core::measures::metrics::Metrics::contacts`]).
    pub contacts: usize,
    /// The largest penetration of the frame's contact pairs, in metres.
    pub max_penetration: f64,
    /// Each body of the scene: its name and the height of its centre of mass.
    pub bodies: Vec<BodyReport>,
}

/// One body of the scene, as the report gives it.
#[derive(Clone, Debug, Serialize)]
pub struct BodyReport {
    /// Its name in the scene.
    pub name: String,
    /// The height (y) of its centre of mass, in metres.
    pub centre_y: f64,
}

/// The Modes window's numbers: the eigenvalues of the selected tet's energy Hessian.
#[derive(Clone, Debug, Serialize)]
pub struct ModesReport {
    /// The tet.
    pub tet: usize,
    /// Its twelve eigenvalues, lowest first.
    pub eigenvalues: Vec<f64>,
    /// How many count as zero.
    pub zero: usize,
    /// How many are negative.
    pub negative: usize,
    /// The mode the view draws, by its place lowest first, if one is picked.
    pub picked: Option<usize>,
}

/// The lesson open.
#[derive(Clone, Debug, Serialize)]
pub struct LessonReport {
    /// Its title.
    pub title: String,
    /// The step shown, from 1.
    pub step: usize,
    /// How many steps it has.
    pub steps: usize,
    /// What the step expects, and whether it holds now.
    pub checks: Vec<CheckReport>,
    /// Frames the step still plays after "Do it".
    pub frames_left: u64,
    /// Whether the step is an exercise (a gradient the student writes or mends).
    pub exercise: bool,
    /// The grade of each gradient the step is an exercise about, as the lesson panel shows it.
    pub grades: Vec<GradeReport>,
}

/// A student's gradient, graded ([`tetlab_core::constraint_file::grade::Grade`]).
#[derive(Clone, Debug, Serialize)]
pub struct GradeReport {
    /// The family graded.
    pub family: String,
    /// Whether every particle's gradient is written and agrees with automatic differentiation.
    pub passed: bool,
    /// What the lesson panel says, a line each.
    pub lines: Vec<String>,
}

/// One expectation of a lesson step.
#[derive(Clone, Debug, Serialize)]
pub struct CheckReport {
    /// The expectation, as the lesson panel writes it.
    pub expect: String,
    /// Whether it holds.
    pub holds: bool,
}

/// Where to drag to invert the selected tet: from its selected particle through the centre of
/// the opposite face, as far again beyond it.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct DragReport {
    /// The selected particle on the screen.
    pub from: [f32; 2],
    /// Its reflection through the opposite face's centre, on the screen.
    pub to: [f32; 2],
}

impl TetlabApp {
    /// What the workbench shows now.
    pub fn report(&self) -> Report {
        let bench = &self.bench;
        let lesson = self.lesson.as_ref().map(|state| {
            let comparison = self.comparison.as_ref().map(|c| &c.bench.metrics);
            let families = bench.simulation.families();
            LessonReport {
                title: state.lesson.title.clone(),
                step: state.step + 1,
                steps: state.lesson.steps.len(),
                checks: state
                    .current()
                    .expect
                    .iter()
                    .map(|e| CheckReport {
                        expect: e.to_string(),
                        holds: e
                            .check(bench.measured(comparison))
                            .is_some_and(|(_, holds)| holds),
                    })
                    .collect(),
                frames_left: state.frames_left,
                exercise: state.current().exercises().next().is_some(),
                grades: state
                    .current()
                    .exercises()
                    .filter_map(|family| {
                        let grade =
                            tetlab_core::constraint_file::grade::of_family(families, family)?;
                        Some(GradeReport {
                            family: families.name(family).to_owned(),
                            passed: grade.passed(),
                            lines: grade.lines().into_iter().map(|(line, _)| line).collect(),
                        })
                    })
                    .collect(),
            }
        });
        Report {
            scene: bench.scene.name.clone(),
            tets: bench.simulation.tets().len(),
            inverted_tets: bench.metrics.inverted_tets,
            frame: bench.simulation.frame(),
            playing: bench.playing,
            error: self.error.clone(),
            notice: self.notice.clone(),
            lesson,
            drag: self.drag_report(),
            modes: self.modes_report(),
            lanes: tetlab_core::numbers::lanes::REGISTERS,
            step_ms: self.step_time.as_secs_f64() * 1e3,
            engine: bench.simulation.describe_engine(),
            contacts: bench.metrics.contacts,
            max_penetration: bench.metrics.max_penetration,
            bodies: bodies(&bench.simulation),
        }
    }

    fn modes_report(&self) -> Option<ModesReport> {
        let tet = self.bench.selected_tet.filter(|_| self.modes.open)?;
        let modes = Modes::of_tet(&self.bench.simulation, tet).ok()?;
        Some(ModesReport {
            tet,
            eigenvalues: modes.values(),
            zero: modes.zero_count(),
            negative: modes.negative_count(),
            picked: self
                .modes
                .picked
                .filter(|_| self.bench.mode_shown.is_some()),
        })
    }

    fn drag_report(&self) -> Option<DragReport> {
        let bench = &self.bench;
        let (tet, particle) = (bench.selected_tet?, bench.selected_particle?);
        let positions = bench.simulation.positions();
        let corners = bench.simulation.tets().get(tet)?;
        let others: Vec<DVec3> = corners
            .iter()
            .filter(|&&i| i as usize != particle)
            .map(|&i| positions[i as usize])
            .collect();
        let centre = others.iter().sum::<DVec3>() / others.len().max(1) as f64;
        let p = positions[particle];
        let beyond = 2.0 * centre - p;
        let (camera, rect) = (&self.viewport.camera, self.viewport.rect);
        let from = viewport::project(camera, rect, p)?.0;
        let to = viewport::project(camera, rect, beyond)?.0;
        Some(DragReport {
            from: [from.x, from.y],
            to: [to.x, to.y],
        })
    }
}

/// Each body's name and the height of its centre of mass (one body for a scene of one).
fn bodies(simulation: &tetlab_core::simulation::Simulation) -> Vec<BodyReport> {
    (tetlab_core::measures::metrics::Metrics::measure_bodies(simulation).into_iter())
        .map(|(name, metrics)| BodyReport {
            name,
            centre_y: metrics.centre_of_mass.y,
        })
        .collect()
}
