//! The workbench's state apart from any widget: the scene, the simulation, what is selected and
//! held, and the recent metrics. Every action a panel or the 3D view offers is a method here.

use super::energy_watch::WorkbenchWatch;
use glam::DVec3;
use std::collections::VecDeque;
use tetlab_core::constraints::{Families, PerFamily};
use tetlab_core::measures::energy_account::Energy;
use tetlab_core::measures::exact_step::ExactStepGap;
use tetlab_core::measures::metrics::{Metrics, penetration_warning};
use tetlab_core::scene::{Builtin, Perturbation, Scene, reflect_through_opposite_face};
use tetlab_core::simulation::divergence::Divergence;
use tetlab_core::simulation::newton::NewtonEngine;
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};
use tetlab_core::teaching::lesson::{Action as LessonAction, Measured};
use tetlab_core::teaching::stepper::{Advanced, StepByStep};

/// The threads the fast engine runs on: every core (one in a browser).
pub fn threads() -> usize {
    if cfg!(target_arch = "wasm32") {
        1
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    }
}

/// How many frames of metrics the plots keep.
pub const HISTORY: usize = 600;

/// One point of the metric plots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Simulated time, seconds.
    pub time: f64,
    /// The metrics at that time.
    pub metrics: Metrics,
    /// The energy account at that time: kinetic, gravitational, elastic and total, J, and the
    /// total with what the ground and damping took since frame 0 added back (what never rises
    /// but by a gain: `tetlab_core::measures::energy_account::EnergyWatch`).
    pub energy: [f64; 5],
    /// How far the frame that led here is from the exact one (the Newton reference's, from the
    /// same start): the largest distance over the particles, m, when [`Workbench::exact_step`]
    /// is on.
    pub exact_step: Option<f64>,
}

/// How long a played frame of the Newton reference may take before playing pauses
/// ([`Workbench::pause_if_slow`]).
pub const SLOW_NEWTON_FRAME: std::time::Duration = std::time::Duration::from_secs(1);

/// The scene being simulated and everything the user has chosen about it.
pub struct Workbench {
    /// The loaded scene (rest shape).
    pub scene: Scene,
    /// The simulation of it.
    pub simulation: Simulation,
    /// Whether frames advance by themselves.
    pub playing: bool,
    /// The selected particle.
    pub selected_particle: Option<usize>,
    /// The selected tet (one containing the selected particle).
    pub selected_tet: Option<usize>,
    /// The particle being dragged.
    pub dragging: Option<usize>,
    /// Recent metrics, oldest first.
    pub history: VecDeque<Sample>,
    /// The metrics of the current state.
    pub metrics: Metrics,
    /// Seed of the next scramble.
    pub scramble_seed: u64,
    /// Step-by-step projection, while that mode is on (paused, one constraint per press).
    pub stepping: Option<StepByStep>,
    /// What the last step-by-step press did.
    pub last_advance: Option<Advanced>,
    /// The simulation diverged (and was put back at rest): why, until the app shows it.
    pub diverged: Option<Divergence>,
    /// Why the settings may blow up ([`Simulation::stability_warning`]), as of the last change
    /// of settings.
    pub stability_warning: Option<String>,
    /// Where the Newton reference steps the simulation and some substep's solve did not
    /// converge, what it says ([`NewtonEngine::warning`]), as of the last step.
    pub newton_warning: Option<String>,
    /// Grows with every change of the simulation's state: what the view compares to know whether
    /// to draw again.
    revision: u64,
    /// The edits made since the scene was loaded or reset, in order (what a link replays;
    /// particles dragged are not among them).
    pub edits: Vec<Edit>,
    /// A mode of a tet's energy Hessian the view shows (the modes panel's pick): drawn only,
    /// the simulation is untouched.
    pub mode_shown: Option<ModeShown>,
    /// Whether each frame is also stepped by the Newton reference from the same start, to show
    /// how far the engine's frame is from the exact one ([`ExactStepGap`]); off by default,
    /// since it solves every substep to 10⁻¹⁰ (slow beyond small scenes).
    pub exact_step: bool,
    /// The last frame's distance from the exact one, when measured.
    pub exact_step_gap: Option<ExactStepGap>,
    /// Why playing paused by itself after a frame of the Newton reference took too long, until
    /// the next play.
    pub slow_frame: Option<String>,
    /// The energy account's watch over the frames played ([`WorkbenchWatch`]).
    energy_watch: WorkbenchWatch,
    /// Where the energy grew past the watch's bound: its warning, as `tetlab run` prints it.
    pub energy_warning: Option<String>,
    /// The largest penetration of the frames played since the last reset, and its frame.
    deepest: (f64, u64),
    /// Where contact let a particle under a surface: the warning `tetlab run` prints
    /// ([`penetration_warning`]).
    pub penetration_warning: Option<String>,
}

/// An eigenmode drawn on a tet: arrows of its eigenvector at the corners, and the tet moved
/// along it ([`tetlab_core::teaching::visual::along_mode`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeShown {
    /// The tet.
    pub tet: usize,
    /// The unit eigenvector: a displacement per corner.
    pub vector: [DVec3; 4],
    /// How far the tet is moved along it, in tet sizes (it changes from frame to frame while
    /// the mode is animated).
    pub offset: f64,
}

/// An edit of the body, made from the tools or by a lesson, that a link can replay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Edit {
    /// A perturbation of the whole body.
    Perturb(Perturbation),
    /// `particle` reflected through the opposite face of `tet` ([`Workbench::invert_selected`]).
    InvertTet {
        /// The tet.
        tet: usize,
        /// Its corner that was reflected.
        particle: usize,
    },
}

impl Workbench {
    /// A workbench on `scene`, paused at rest, with tet 0 and its first corner selected.
    pub fn new(scene: Scene, settings: Settings) -> Self {
        Workbench::with_families(scene, settings, Families::builtin())
    }

    /// [`Workbench::new`] on the families of `families`.
    pub fn with_families(scene: Scene, settings: Settings, families: Families) -> Self {
        let mut simulation = Simulation::with_families(&scene, settings, families);
        simulation.set_threads(threads());
        let mut workbench = Workbench {
            stability_warning: simulation.stability_warning(),
            newton_warning: None,
            scene,
            metrics: Metrics::measure(&simulation),
            simulation,
            playing: false,
            selected_particle: None,
            selected_tet: None,
            dragging: None,
            history: VecDeque::with_capacity(HISTORY),
            scramble_seed: 1,
            stepping: None,
            last_advance: None,
            diverged: None,
            revision: 0,
            edits: Vec::new(),
            mode_shown: None,
            exact_step: false,
            exact_step_gap: None,
            slow_frame: None,
            energy_watch: WorkbenchWatch::default(),
            energy_warning: None,
            deepest: (0.0, 0),
            penetration_warning: None,
        };
        workbench.select_tet(0);
        workbench.record();
        workbench
    }

    /// A built-in scene at a resolution (clamped to what [`Scene::builtin`] accepts).
    pub fn builtin(builtin: Builtin, resolution: u32, settings: Settings) -> Self {
        let resolution = resolution.clamp(1, 16);
        let scene = Scene::builtin(builtin, resolution).expect("resolution is in range");
        Workbench::new(scene, settings)
    }

    /// A second workbench in the same state (scene, positions, velocities, selection) but with
    /// other constraint families: the right half of a comparison.
    pub fn twin(&self, active: PerFamily<bool>) -> Workbench {
        let settings = Settings {
            active,
            ..*self.simulation.settings()
        };
        let mut twin = Workbench::new(self.scene.clone(), settings);
        twin.simulation = self.simulation.clone();
        twin.simulation.set_settings(settings);
        twin.simulation.release();
        twin.playing = self.playing;
        twin.selected_particle = self.selected_particle;
        twin.selected_tet = self.selected_tet;
        twin.scramble_seed = self.scramble_seed;
        twin.edits = self.edits.clone();
        twin.after_change();
        twin
    }

    /// Replaces the scene, keeping the settings.
    pub fn load(&mut self, scene: Scene) {
        let families = self.simulation.families().clone();
        // A revision the view has not drawn: a new workbench's would start again where the
        // old one's may have stood, and the view would keep showing the old scene.
        let revision = self.revision + 1;
        *self = Workbench::with_families(scene, *self.simulation.settings(), families);
        self.revision = self.revision.max(revision);
    }

    /// After a played frame that took `took`: where the Newton reference stepped it (as the
    /// engine, or for the distance from the exact step) and it took longer than
    /// [`SLOW_NEWTON_FRAME`], pauses and says why, so that a large or tangled scene does not hold
    /// the window frozen frame after frame (each frame is solved on the window's thread). Step
    /// frame goes on one frame at a time. Returns whether it paused.
    pub fn pause_if_slow(&mut self, took: std::time::Duration) -> bool {
        let newton = self.exact_step || self.simulation.engine() == EngineChoice::Newton;
        if !(self.playing && newton && took > SLOW_NEWTON_FRAME) {
            return false;
        }
        self.set_playing(false);
        self.slow_frame = Some(format!(
            "paused: the Newton reference took {:.1} s for the last frame (every substep solved \
             exactly); Step frame goes on one frame at a time",
            took.as_secs_f64()
        ));
        true
    }

    /// Advances one frame. On the page's GPU engine a call may only start the frame
    /// ([`Simulation::pending`](tetlab_core::simulation::Simulation::pending)): nothing changes
    /// until a later call finishes it, and the watches read the state the frame started from
    /// then (it is the same, or the edit made since, from which the frame is stepped again).
    pub fn step_frame(&mut self) {
        self.leave_step_mode();
        let before = self.exact_step.then(|| self.simulation.clone());
        self.energy_watch.before_frame(&self.simulation);
        self.simulation.step();
        if self.simulation.pending() {
            return;
        }
        self.energy_warning = self.energy_watch.after_frame(&self.simulation);
        self.exact_step_gap = before.map(|before| ExactStepGap::measure(&before, &self.simulation));
        // The engine that just stepped is ready: asking for it builds nothing.
        self.newton_warning =
            (self.simulation.engine_as::<NewtonEngine>()).and_then(|newton| newton.warning());
        self.after_change();
        if self.metrics.max_penetration > self.deepest.0 {
            self.deepest = (self.metrics.max_penetration, self.simulation.frame());
        }
        let thickness = self.simulation.settings().contact.thickness;
        self.penetration_warning = penetration_warning(self.deepest.0, self.deepest.1, thickness);
    }

    /// Advances one substep (Δt / substeps), without counting a frame.
    pub fn step_substep(&mut self) {
        self.leave_step_mode();
        self.simulation.substep();
        self.after_change();
    }

    /// Step-by-step mode: pauses, then does the next single thing of a substep — begin it
    /// (predict), project one constraint, or close a sweep.
    pub fn step_projection(&mut self) {
        self.set_playing(false);
        let stepper = self.stepping.get_or_insert_default();
        self.last_advance = Some(stepper.advance(&mut self.simulation));
        self.after_change();
    }

    /// Step-by-step mode: makes the remaining projections of the substep under way and ends it,
    /// staying in the mode.
    pub fn finish_substep(&mut self) {
        if let Some(stepper) = &mut self.stepping {
            stepper.finish(&mut self.simulation);
            self.last_advance = None;
            self.after_change();
        }
    }

    /// Ends step-by-step mode, finishing the substep under way so that the simulation stands
    /// between substeps (every edit and every other kind of step starts from there).
    pub fn leave_step_mode(&mut self) {
        if let Some(mut stepper) = self.stepping.take() {
            stepper.finish(&mut self.simulation);
            self.last_advance = None;
        }
    }

    /// What a lesson's expectations are checked against: this simulation, its selected tet (tet
    /// 0 when none is), its metrics, and `comparison`'s.
    pub fn measured<'a>(&'a self, comparison: Option<&'a Metrics>) -> Measured<'a> {
        Measured {
            simulation: &self.simulation,
            tet: self.selected_tet.unwrap_or(0),
            metrics: &self.metrics,
            comparison,
        }
    }

    /// Back to the rest shape.
    pub fn reset(&mut self) {
        self.energy_watch.stop();
        self.energy_warning = None;
        (self.deepest, self.penetration_warning) = ((0.0, 0), None);
        self.stepping = None;
        self.last_advance = None;
        self.simulation.reset();
        self.history.clear();
        self.edits.clear();
        self.after_change();
    }

    /// Applies a perturbation to the whole body.
    pub fn perturb(&mut self, perturbation: Perturbation) {
        self.finish_substep();
        self.simulation.perturb(perturbation);
        self.edits.push(Edit::Perturb(perturbation));
        self.after_change();
    }

    /// Scrambles with the next seed.
    pub fn scramble(&mut self) {
        self.perturb(Perturbation::Scramble(self.scramble_seed));
        self.scramble_seed += 1;
    }

    /// Makes `edit` again (a link's edits, replayed); an edit that does not fit this body (a tet
    /// it does not have, or a particle not its corner) is refused with a message.
    pub fn apply_edit(&mut self, edit: Edit) -> Result<(), String> {
        match edit {
            Edit::Perturb(perturbation) => self.perturb(perturbation),
            Edit::InvertTet { tet, particle } => {
                let tets = self.simulation.tets();
                let Some(corners) = tets.get(tet) else {
                    return Err(format!("tet {tet} is not in a body of {} tets", tets.len()));
                };
                if !corners.contains(&(particle as u32)) {
                    return Err(format!("particle {particle} is not a corner of tet {tet}"));
                }
                self.selected_tet = Some(tet);
                self.selected_particle = Some(particle);
                self.invert_selected();
            }
        }
        Ok(())
    }

    /// Reflects the selected particle through the opposite face of the selected tet: that tet
    /// inverts with its edge lengths kept.
    pub fn invert_selected(&mut self) {
        let (Some(particle), Some(tet)) = (self.selected_particle, self.selected_tet) else {
            return;
        };
        let corners = self.simulation.tets()[tet];
        let Some(k) = corners.iter().position(|&i| i as usize == particle) else {
            return;
        };
        self.finish_substep();
        let mut positions = self.simulation.positions().to_vec();
        reflect_through_opposite_face(&mut positions, &corners, k);
        self.simulation.place(particle, positions[particle]);
        self.edits.push(Edit::InvertTet { tet, particle });
        self.after_change();
    }

    /// Pins the selected particle, or frees it if pinned.
    pub fn toggle_pin(&mut self) {
        if let Some(i) = self.selected_particle {
            let pinned = self.simulation.is_pinned(i);
            self.simulation.set_pinned(i, !pinned);
            self.revision += 1;
        }
    }

    /// Selects a particle and the first tet that contains it.
    pub fn select_particle(&mut self, particle: usize) {
        self.selected_particle = Some(particle);
        let first = self.tets_of(particle).next();
        self.selected_tet = first;
    }

    /// Selects a tet and its first corner.
    pub fn select_tet(&mut self, tet: usize) {
        if let Some(corners) = self.simulation.tets().get(tet) {
            self.selected_tet = Some(tet);
            self.selected_particle = Some(corners[0] as usize);
        }
    }

    /// Selects the next tet that contains the selected particle.
    pub fn next_tet_of_selected(&mut self) {
        let Some(particle) = self.selected_particle else {
            return;
        };
        let tets: Vec<usize> = self.tets_of(particle).collect();
        if tets.is_empty() {
            return;
        }
        let at = self
            .selected_tet
            .and_then(|t| tets.iter().position(|&x| x == t));
        self.selected_tet = Some(tets[at.map_or(0, |i| (i + 1) % tets.len())]);
    }

    fn tets_of(&self, particle: usize) -> impl Iterator<Item = usize> + '_ {
        self.simulation
            .tets()
            .iter()
            .enumerate()
            .filter(move |(_, t)| t.contains(&(particle as u32)))
            .map(|(i, _)| i)
    }

    /// Starts dragging a particle toward `target`: held by the grab constraint while playing,
    /// moved directly (kinematically) while paused.
    pub fn start_drag(&mut self, particle: usize, target: DVec3) {
        self.finish_substep();
        self.select_particle(particle);
        self.dragging = Some(particle);
        if self.playing {
            self.simulation.grab(particle, target);
        } else {
            self.simulation.place(particle, target);
            self.after_change();
        }
    }

    /// Moves the dragged particle's target.
    pub fn drag_to(&mut self, target: DVec3) {
        let Some(particle) = self.dragging else {
            return;
        };
        if self.simulation.grabbed().is_some() {
            self.simulation.move_grab(target);
        } else {
            self.simulation.place(particle, target);
            self.after_change();
        }
    }

    /// Lets go of the dragged particle.
    pub fn end_drag(&mut self) {
        self.dragging = None;
        self.simulation.release();
    }

    /// Starts or stops playing; a drag in progress switches between grab and kinematic moves.
    /// Playing ends step-by-step mode.
    pub fn set_playing(&mut self, playing: bool) {
        if playing {
            self.leave_step_mode();
            self.slow_frame = None;
        }
        self.playing = playing;
        if let Some(particle) = self.dragging {
            let position = self.simulation.positions()[particle];
            if playing {
                self.simulation.grab(particle, position);
            } else {
                self.simulation.release();
                self.simulation.place(particle, position);
            }
        }
    }

    /// Does one action of a lesson step (a [`LessonAction::Compare`] is the app's business).
    pub fn apply_lesson_action(&mut self, action: LessonAction) {
        match action {
            LessonAction::Reset => self.reset(),
            LessonAction::Select(tet) => self.select_tet(tet),
            LessonAction::Compare(_) => {}
            other => {
                self.finish_substep();
                let mut tet = self.selected_tet.unwrap_or(0);
                other.apply(&mut self.simulation, &mut tet);
                self.after_change();
            }
        }
    }

    /// Changes the solver settings. Step-by-step mode first finishes its substep under the old
    /// settings.
    pub fn set_settings(&mut self, settings: Settings) {
        if settings != *self.simulation.settings() {
            self.finish_substep();
        }
        self.simulation.set_settings(settings);
        self.stability_warning = self.simulation.stability_warning();
        self.after_change();
    }

    /// Simulates the families of `families` from now on (a constraint file defined or
    /// redefined by the editor, a lesson's): step-by-step mode ends where it stands (its next
    /// constraint may be gone), and the constraints of a redefined family are rebuilt.
    pub fn set_families(&mut self, families: Families) {
        self.stepping = None;
        self.last_advance = None;
        self.simulation.set_families(families);
        self.after_change();
    }

    /// Which state of the simulation this is: it grows with every step and edit.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Measures the new state. A state that diverged is never drawn or plotted: the body goes
    /// back to rest, paused, and [`Workbench::diverged`] says why.
    fn after_change(&mut self) {
        self.revision += 1;

        match Metrics::measure_sound(&self.simulation) {
            Ok(metrics) => self.metrics = metrics,
            Err(divergence) => {
                self.diverged = Some(divergence);
                self.stepping = None;
                self.last_advance = None;
                self.dragging = None;
                self.playing = false;
                self.simulation.release();
                self.simulation.reset();
                self.history.clear();
                self.metrics = Metrics::measure(&self.simulation);
            }
        }
        self.record();
    }

    fn record(&mut self) {
        if self.history.len() == HISTORY {
            self.history.pop_front();
        }
        let energy = Energy::measure(&self.simulation);
        let elastic: f64 = (self.simulation.families().all())
            .map(|f| energy.elastic[f])
            .sum();
        self.history.push_back(Sample {
            time: self.simulation.time(),
            metrics: self.metrics,
            energy: [
                energy.kinetic,
                energy.gravitational,
                elastic,
                energy.total,
                energy.total + energy.taken.ground + energy.taken.damping,
            ],
            // Each frame's gap is plotted once: the samples of edits after it have none.
            exact_step: self.exact_step_gap.take().map(|gap| gap.largest),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Newton reference allowed one Newton iteration a substep: it cannot converge.
    fn one_iteration(
        _: tetlab_core::simulation::Start<'_>,
    ) -> Box<dyn tetlab_core::simulation::Engine> {
        let options = tetlab_core::simulation::newton::Options {
            max_iterations: 1,
            max_outer_iterations: 1,
            ..Default::default()
        };
        Box::new(NewtonEngine::with_options(options))
    }

    #[test]
    fn with_the_exact_step_on_each_frame_is_measured_against_the_newton_reference() {
        let mut bench = Workbench::builtin(Builtin::Tet, 1, Settings::default());
        bench.step_frame();
        assert_eq!(
            bench.history.back().unwrap().exact_step,
            None,
            "off by default"
        );
        bench.exact_step = true;
        bench.step_frame();
        // A tet resting on the ground: XPBD's frame sags by its solver's error, a small part of
        // the frame's motion (gravity's, undone by the ground and the constraints).
        let gap = bench.history.back().unwrap().exact_step.expect("measured");
        assert!(gap > 0.0 && gap.is_finite(), "{gap}");
        bench.perturb(Perturbation::Flatten);
        assert_eq!(
            bench.history.back().unwrap().exact_step,
            None,
            "an edit is no frame"
        );
    }

    #[test]
    fn a_slow_newton_frame_pauses_playing_and_says_why() {
        use std::time::Duration;
        let mut bench = Workbench::builtin(Builtin::Tet, 1, Settings::default());
        bench.set_playing(true);
        let slow = SLOW_NEWTON_FRAME + Duration::from_millis(1);
        assert!(!bench.pause_if_slow(slow), "no Newton reference steps it");
        bench.exact_step = true;
        assert!(!bench.pause_if_slow(SLOW_NEWTON_FRAME / 2), "fast enough");
        assert!(bench.playing);
        assert!(bench.pause_if_slow(slow));
        assert!(!bench.playing);
        let why = bench.slow_frame.clone().unwrap();
        assert!(
            why.starts_with("paused: the Newton reference took 1.0 s"),
            "{why}"
        );
        bench.set_playing(true);
        assert_eq!(bench.slow_frame, None, "playing again clears it");
    }

    #[test]
    fn the_readouts_warn_when_the_newton_reference_did_not_converge() {
        let mut bench = Workbench::builtin(Builtin::Cube, 1, Settings::default());
        bench.step_frame();
        assert_eq!(bench.newton_warning, None, "the reference engine steps it");
        bench
            .simulation
            .use_engine(one_iteration, "newton, one iteration");
        bench.perturb(Perturbation::Flatten);
        bench.step_frame();
        let warning = bench.newton_warning.clone().expect("a warning");
        assert!(
            warning.starts_with("the Newton reference did not solve"),
            "{warning}"
        );
    }

    #[test]
    fn inverting_the_selected_tet_then_playing_recovers_it() {
        let mut bench = Workbench::builtin(Builtin::Cube, 2, Settings::default());
        bench.select_tet(5);
        bench.invert_selected();
        assert!(bench.metrics.inverted_tets >= 1);
        bench.set_playing(true);
        for _ in 0..60 {
            bench.step_frame();
        }
        assert_eq!(bench.metrics.inverted_tets, 0);
    }

    #[test]
    fn a_paused_drag_moves_the_particle_and_a_running_drag_pulls_it() {
        let mut bench = Workbench::builtin(
            Builtin::Cube,
            2,
            Settings {
                gravity: 0.0,
                ground: false,
                ..Settings::default()
            },
        );
        let target = bench.simulation.positions()[0] + DVec3::new(0.0, 0.0, -0.3);
        bench.start_drag(0, target);
        assert_eq!(
            bench.simulation.positions()[0],
            target,
            "paused: the particle goes where it is put"
        );
        bench.end_drag();
        bench.set_playing(true);
        let start = bench.simulation.positions()[3];
        let pulled = start + DVec3::new(0.0, 0.5, 0.0);
        bench.start_drag(3, pulled);
        bench.step_frame();
        assert_eq!(
            bench.simulation.positions()[3],
            pulled,
            "running: held rigidly by the grab"
        );
        bench.end_drag();
        assert!(bench.simulation.inverse_masses()[3] > 0.0);
    }

    #[test]
    fn selection_cycles_through_the_tets_of_a_particle() {
        let mut bench = Workbench::builtin(Builtin::Cube, 2, Settings::default());
        bench.select_particle(13);
        let first = bench.selected_tet.unwrap();
        bench.next_tet_of_selected();
        assert_ne!(bench.selected_tet, Some(first));
        assert!(bench.simulation.tets()[bench.selected_tet.unwrap()].contains(&13));
    }

    #[test]
    fn a_simulation_that_diverges_goes_back_to_rest_and_says_why() {
        let mut bench = Workbench::builtin(Builtin::Cube, 2, Settings::default());
        // What no setting of the controls allows: a compliance whose α / h² is infinite.
        let mut settings = *bench.simulation.settings();
        settings.compliance[tetlab_core::constraints::Family::VOLUME] = 1e305;
        bench.set_settings(settings);
        bench.select_tet(0);
        bench.invert_selected();
        bench.set_playing(true);
        bench.step_frame();
        let divergence = bench
            .diverged
            .take()
            .expect("the volume projections gave NaN");
        assert!(
            divergence.to_string().contains("diverged at frame"),
            "{divergence}"
        );
        assert!(!bench.playing);
        assert!(bench.simulation.is_sound());
        assert_eq!(
            bench.simulation.positions(),
            bench.simulation.rest_positions()
        );
        assert!(bench.metrics.volume_error.is_finite());
    }

    #[test]
    fn pins_toggle_and_history_is_bounded() {
        let mut bench = Workbench::builtin(Builtin::Tet, 1, Settings::default());
        bench.select_particle(2);
        bench.toggle_pin();
        assert!(bench.simulation.is_pinned(2));
        bench.toggle_pin();
        assert!(!bench.simulation.is_pinned(2));
        for _ in 0..HISTORY + 10 {
            bench.step_frame();
        }
        assert_eq!(bench.history.len(), HISTORY);
    }

    /// The readouts warn where the energy grows, as `tetlab run` does: the cube under its volume
    /// constraint alone (lesson 4's first step: XPBD's step on slivers gives energy) warns; at
    /// rest under the default families, and while a particle is held (its pull does work), it
    /// does not; a reset forgets the warning.
    #[test]
    fn the_readouts_warn_where_the_energy_grows() {
        let settings = Settings {
            active: PerFamily::builtin_list("volume").unwrap(),
            substeps: 10,
            ..Settings::default()
        };
        let mut bench = Workbench::builtin(Builtin::Cube, 4, settings);
        for _ in 0..120 {
            bench.step_frame();
        }
        let warning = bench
            .energy_warning
            .clone()
            .expect("the volume alone gains");
        assert!(warning.contains("the energy grew"), "{warning}");
        bench.reset();
        assert_eq!(bench.energy_warning, None);

        let mut bench = Workbench::builtin(Builtin::Cube, 4, Settings::default());
        for _ in 0..60 {
            bench.step_frame();
        }
        assert_eq!(bench.energy_warning, None);
        bench.simulation.grab(0, DVec3::new(0.0, 5.0, 0.0));
        for _ in 0..30 {
            bench.step_frame();
        }
        assert_eq!(
            bench.energy_warning, None,
            "a held particle's pull is not a gain"
        );
    }
}
