//! What a panel asks of the app: one type for every panel. Panels draw and add requests; the app
//! carries them out in one loop once every panel is drawn (the pattern of egui's demo library),
//! so that no panel changes what another is still drawing.

use super::panels::controls::SceneRequest;
use super::panels::lesson::LessonRequest;
use super::shortcuts::Action;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::PerFamily;
use tetlab_core::solver::Settings;

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
    Constraint(Box<ConstraintFile>),
}
