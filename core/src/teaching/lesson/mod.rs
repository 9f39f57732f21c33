//! Lessons: a scene, solver settings and a sequence of steps, written as TOML files so that a
//! teacher can make one without Rust. Each step has text, the actions that show its point, how
//! many frames to run after them, and the observations it expects, which are checked against the
//! metrics (live in the workbench, at the end of the step when run headless).
//!
//! ```toml
//! title = "Why edges alone cannot un-invert a tet"
//! scene = "tet"              # a built-in (tet, cube, beam, ball) or a mesh path, relative to the file
//! resolution = 1             # optional, for built-ins
//! tet = 0                    # optional: the tet whose arrows are shown
//!
//! [settings]                 # optional; the names of the command line
//! constraints = "edges"      # engine = "reference" if the lesson needs the f64 solver
//! gravity = 0
//!
//! [[step]]
//! text = "Mirror the tet: every edge keeps its length."
//! actions = ["mirror"]
//! frames = 60
//! expect = ["inverted_tets == 1", "max_edge_strain < 1e-6"]
//! ```
//!
//! A lesson may bring constraint files (`constraint_files = ["../constraints/height.toml"]`,
//! relative to the lesson): their families join the table when it is read, and its settings and
//! steps name them like the built-in ones; `gradient_error.NAME` measures how far such a file's
//! gradient is from automatic differentiation ([`GRADIENT_ERROR`]). `zero_modes` and
//! `negative_modes` count the eigenvalues of the selected tet's energy Hessian that are zero and
//! negative ([`MODE_METRICS`]).
//!
//! Actions: `reset`, `invert` (the lesson's tet, through its first corner), `invert:K`, `mirror`,
//! `flatten`, `scramble:SEED`, `select:K`, `constraints:LIST`, `solver:xpbd|pbd`,
//! `compliance:FAMILY=α`, `stiffness:FAMILY=k`, `substeps:N`, `iterations:N`, `gravity:G`,
//! `compare:LIST` (show a second simulation of the same scene with other constraint families
//! beside the first) and `compare:off`. Expectations: `METRIC OP NUMBER` with a metric of
//! [`Metrics::headline`] (`compare.METRIC` for the comparison's) and OP one of `==`, `!=`, `<`,
//! `<=`, `>`, `>=`.

use crate::constraint_file::ConstraintFile;
use crate::constraints::material::Material;
use crate::constraints::{Families, Family, PerFamily};
use crate::input::limits::{self, Bounds};
use crate::measures::metrics::Metrics;
use crate::scene::{Perturbation, Scene, SceneError, reflect_through_opposite_face};
use crate::simulation::divergence::Divergence;
use crate::simulation::{EngineChoice, Method, Settings, Simulation};
use std::collections::BTreeMap;
use std::fmt;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use toml::Spanned;

mod action;
mod builtin;
mod expectation;
mod format;
mod runner;
#[cfg(test)]
mod tests;

pub use action::Action;
pub use builtin::{BUILTIN, BuiltinLesson, LessonHeader};
pub use expectation::{Expectation, GRADIENT_ERROR, MODE_METRICS, Measured, ModeCount, Op};
pub use format::MAX_STEP_FRAMES;
pub use runner::{LessonRun, StepOutcome};

/// A lesson, parsed and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Lesson {
    /// Its title.
    pub title: String,
    /// The file it came from (or the name it was given).
    pub source: PathBuf,
    /// The scene: a built-in name or a mesh path (already resolved against the lesson's folder).
    pub scene: String,
    /// The resolution of a built-in scene.
    pub resolution: u32,
    /// The families of the constraint files the lesson names (`constraint_files`), in
    /// [`Lesson::families`].
    pub file_families: Vec<Family>,
    /// The table of families the lesson simulates: the built-in ones and its constraint files
    /// ([`Families::define`]).
    pub families: Families,
    /// The tet whose arrows are shown at the start.
    pub tet: usize,
    /// The solver settings at the start.
    pub settings: Settings,
    /// The steps, in order.
    pub steps: Vec<Step>,
    /// The scene as it was built when the lesson was read ([`Lesson::scene`] gives it again).
    built: Scene,
}

/// One step of a lesson.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// What the step explains and asks the reader to try.
    pub text: String,
    /// What the step does when run ("Do it" in the workbench, always when headless).
    pub actions: Vec<Action>,
    /// Frames to run after the actions.
    pub frames: u64,
    /// What should be observed after the actions and frames.
    pub expect: Vec<Expectation>,
}

/// Why a lesson could not be read: the file, the line, and what is wrong there.
#[derive(Clone, Debug, PartialEq)]
pub struct LessonError {
    /// The lesson file.
    pub path: PathBuf,
    /// The line (from 1), when the problem has one.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for LessonError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.path.display(), self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for LessonError {}
