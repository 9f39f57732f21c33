//! A lesson run headless, step by step: the actions done, the frames run, the expectations
//! checked.

use super::*;
use crate::measures::energy_account::EnergyWatch;

/// One step's outcome when a lesson runs headless.
#[derive(Clone, Debug, PartialEq)]
pub struct StepOutcome {
    /// Each expectation with the metric's value at the end of the step (`None`: about a
    /// comparison that is not shown) and whether it held.
    pub checks: Vec<(Expectation, Option<f64>, bool)>,
}

impl Step {
    /// The families whose gradient this step expects to agree with automatic differentiation
    /// (`gradient_error.NAME < …`): the step is an exercise about their files.
    pub fn exercises(&self) -> impl Iterator<Item = Family> + '_ {
        self.expect.iter().filter_map(|e| {
            e.gradient_of
                .filter(|_| matches!(e.op, Op::Less | Op::LessOrEqual))
        })
    }
}

/// A lesson running headless: the simulation, the selected tet, and the comparison simulation
/// when a step asked for one.
pub struct LessonRun {
    /// The lesson's simulation.
    pub simulation: Simulation,
    /// The second simulation, with other constraint families, while a step compares.
    pub comparison: Option<Simulation>,
    /// The selected tet.
    pub tet: usize,
    scene: Scene,
    /// The metrics of both simulations, as last measured by [`LessonRun::measure`].
    metrics: (Metrics, Option<Metrics>),
    /// Answers handed in ([`LessonRun::hand_in`]) not yet taken up.
    answers: Vec<ConstraintFile>,
    /// The energy account of the simulation over the current step's frames, from the state its
    /// actions left (an action such as a perturbation gives energy; the frames after it must
    /// not).
    energy: EnergyWatch,
}

impl LessonRun {
    /// The lesson's scene at rest with its settings.
    pub fn new(lesson: &Lesson) -> LessonRun {
        let scene = lesson.scene();
        let simulation =
            Simulation::with_families(&scene, lesson.settings, lesson.families.clone());
        LessonRun {
            metrics: (Metrics::measure(&simulation), None),
            energy: EnergyWatch::start(&simulation),
            simulation,
            comparison: None,
            tet: lesson.tet,
            scene,
            answers: Vec::new(),
        }
    }

    /// A student's answer to an exercise of the lesson: a constraint file with the name of one
    /// the lesson brings. It replaces that file's family from the first step that expects its
    /// gradient to agree ([`Step::exercises`]), as the student's edits in the workbench would:
    /// the steps before it still show the lesson's own file.
    ///
    /// An error when no step of `lesson` is an exercise about a family of that name.
    pub fn hand_in(&mut self, lesson: &Lesson, answer: ConstraintFile) -> Result<(), String> {
        let asked = lesson
            .steps
            .iter()
            .flat_map(Step::exercises)
            .any(|family| lesson.families.name(family) == answer.name);
        if !asked {
            return Err(format!(
                "{} defines {}, and no step of this lesson is an exercise about {0}",
                answer.path.display(),
                answer.name
            ));
        }
        self.answers.push(answer);
        Ok(())
    }

    /// Applies one action to the simulation and to the comparison.
    pub fn apply(&mut self, action: Action) {
        if let Action::Compare(families) = action {
            self.comparison = families.map(|active| {
                let mut comparison = self.simulation.clone();
                let settings = Settings {
                    active,
                    ..*self.simulation.settings()
                };
                comparison.set_settings(settings);
                comparison
            });
            return;
        }
        let mut ignored = self.tet;
        action.apply(&mut self.simulation, &mut self.tet);
        if let Some(comparison) = &mut self.comparison
            && action.applies_to_comparison()
        {
            action.apply(comparison, &mut ignored);
        }
    }

    /// Advances both simulations one frame.
    pub fn step(&mut self) {
        self.simulation.step();
        if let Some(comparison) = &mut self.comparison {
            comparison.step();
        }
    }

    /// Measures both simulations ([`Metrics::measure_sound`]): an error naming the one that
    /// diverged, if one did.
    pub fn measure(&mut self) -> Result<(), Divergence> {
        let main = Metrics::measure_sound(&self.simulation)?;
        let comparison = match &self.comparison {
            Some(c) => Some(Metrics::measure_sound(c).map_err(|d| d.of("the comparison"))?),
            None => None,
        };
        self.metrics = (main, comparison);
        Ok(())
    }

    /// The metrics of the simulation and of the comparison (if one is shown) at the last
    /// [`LessonRun::measure`]: finite, since it checked them.
    pub fn metrics(&self) -> (&Metrics, Option<&Metrics>) {
        (&self.metrics.0, self.metrics.1.as_ref())
    }

    /// The energy account of the simulation over the current (or last) step's frames, from the
    /// state the step's actions left: frame k is the step's k-th.
    pub fn energy(&self) -> &EnergyWatch {
        &self.energy
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Runs a whole step: actions, frames (measuring both simulations after each, then calling
    /// `on_frame`, which may stop the step early by returning [`ControlFlow::Break`]), then the
    /// checks. `Ok(None)` when stopped early; an error when a simulation diverged, so that
    /// nothing after it is shown or checked.
    pub fn run_step(
        &mut self,
        step: &Step,
        mut on_frame: impl FnMut(&LessonRun) -> ControlFlow<()>,
    ) -> Result<Option<StepOutcome>, Divergence> {
        let exercises: Vec<Family> = step.exercises().collect();
        let (taken, kept): (Vec<_>, Vec<_>) = std::mem::take(&mut self.answers)
            .into_iter()
            .partition(|a| {
                let families = self.simulation.families();
                exercises.iter().any(|&f| families.name(f) == a.name)
            });
        self.answers = kept;
        for answer in taken {
            // Its name is a family's already (hand_in checked): it is redefined in place, which
            // cannot fail.
            let mut families = self.simulation.families().clone();
            let _ = families.define(answer);
            if let Some(comparison) = &mut self.comparison {
                comparison.set_families(families.clone());
            }
            self.simulation.set_families(families);
        }
        for &action in &step.actions {
            self.apply(action);
        }
        self.measure()?;
        self.energy = EnergyWatch::start(&self.simulation);
        for frame in 1..=step.frames {
            self.step();
            self.measure()?;
            self.energy.observe(&self.simulation, frame);
            if on_frame(self).is_break() {
                return Ok(None);
            }
        }
        Ok(Some(self.check(step)))
    }

    /// The step's expectations against the metrics of the last [`LessonRun::measure`].
    pub fn check(&self, step: &Step) -> StepOutcome {
        let (metrics, comparison) = self.metrics();
        StepOutcome {
            checks: step
                .expect
                .iter()
                .map(|e| {
                    let measured = Measured {
                        simulation: &self.simulation,
                        tet: self.tet,
                        metrics,
                        comparison,
                    };
                    match e.check(measured) {
                        Some((value, holds)) => (e.clone(), Some(value), holds),
                        None => (e.clone(), None, false),
                    }
                })
                .collect(),
        }
    }
}
