//! What a panel asks of the app: one type for every panel. Panels draw and add requests; the app
//! carries them out in one loop once every panel is drawn (the pattern of egui's demo library),
//! so that no panel changes what another is still drawing.

use super::shortcuts::Action;
use super::workbench::ModeShown;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::PerFamily;
use tetlab_core::scene::Builtin;
use tetlab_core::simulation::Settings;

/// One thing the user asked for in a panel.
#[derive(Debug)]
pub enum Request {
    /// What a key or a button does (play, reset, invert, open the inspector, …).
    Act(Action),
    /// A scene to load: a built-in one or a mesh file.
    Scene(SceneRequest),
    /// A lesson to open, or its step to do, or to move between its steps.
    Lesson(LessonRequest),
    /// Compare side by side with these families, or stop comparing (`None`).
    Compare(Option<PerFamily<bool>>),
    /// New solver settings, for every simulation shown.
    Settings(Box<Settings>),
    /// A constraint file the editor compiled: its family is (re)defined and switched on.
    Constraint(Vec<ConstraintFile>),
    /// Show this mode of a tet's energy Hessian in the view, or none.
    ShowMode(Option<ModeShown>),
    /// Measure each frame's distance from the exact one (the Newton reference's), or stop.
    ExactStep(bool),
}

/// A scene the user asked for.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneRequest {
    /// A built-in scene at a resolution.
    Builtin(Builtin, u32),
    /// A mesh file.
    File(String),
    /// A built-in at a resolution added to the scene shown as one more body, dropped onto it
    /// ([`tetlab_core::scene::Scene::with_body_dropped`]).
    AddBody(Builtin, u32),
    /// A scene file that comes with tetlab, by its file name
    /// ([`tetlab_core::scene::ShippedScene`]).
    Shipped(&'static str),
}

/// What the user asked of the lesson panel.
#[derive(Clone, Debug, PartialEq)]
pub enum LessonRequest {
    /// Open built-in lesson k (from 1).
    Builtin(usize),
    /// Open a lesson file.
    File(String),
    /// Do the step's actions and play its frames.
    Do,
    /// The next step.
    Next,
    /// The previous step.
    Previous,
}
