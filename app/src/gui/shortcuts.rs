//! The keyboard shortcuts: one table, read by the key handler and by the help panel.

use eframe::egui::Key;

/// Something a key does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Play or pause.
    PlayPause,
    /// Advance one frame.
    StepFrame,
    /// Advance one substep.
    StepSubstep,
    /// Step-by-step: the next single projection (or prediction, or end of sweep).
    StepProjection,
    /// Step-by-step: finish the substep under way.
    FinishSubstep,
    /// Back to the rest shape.
    Reset,
    /// Invert the selected tet.
    InvertSelected,
    /// Mirror the whole body.
    Mirror,
    /// Flatten the whole body.
    Flatten,
    /// Scramble the whole body.
    Scramble,
    /// Pin or free the selected particle.
    TogglePin,
    /// Select the next tet of the selected particle.
    NextTet,
    /// Frame the body in the view.
    FrameView,
    /// Back to the first camera view.
    ResetCamera,
    /// Show or hide the inspector.
    Inspector,
    /// Show or hide the modes of the selected tet's energy.
    Modes,
    /// Show or hide the lesson window.
    Lesson,
    /// Show or hide the constraint editor.
    ConstraintEditor,
    /// Open a mesh or lesson file.
    OpenFile,
    /// Classroom mode on or off.
    Classroom,
    /// The lesson's next step.
    NextStep,
    /// The lesson's previous step.
    PreviousStep,
    /// Do what the lesson step does (its actions, then its frames).
    DoStep,
    /// Show or hide the help.
    Help,
    /// Copy a link to this state (a button; no key).
    CopyLink,
}

/// Every shortcut: key, action, what the help says.
pub const SHORTCUTS: [(Key, Action, &str); 24] = [
    (Key::Space, Action::PlayPause, "play / pause"),
    (Key::N, Action::StepFrame, "step one frame"),
    (Key::U, Action::StepSubstep, "step one substep"),
    (
        Key::J,
        Action::StepProjection,
        "step by step: the next projection",
    ),
    (
        Key::K,
        Action::FinishSubstep,
        "step by step: finish the substep",
    ),
    (Key::R, Action::Reset, "reset to rest"),
    (Key::I, Action::InvertSelected, "invert the selected tet"),
    (Key::M, Action::Mirror, "mirror everything"),
    (Key::F, Action::Flatten, "flatten everything"),
    (Key::S, Action::Scramble, "scramble"),
    (
        Key::P,
        Action::TogglePin,
        "pin / unpin the selected particle",
    ),
    (Key::T, Action::NextTet, "next tet of the selected particle"),
    (Key::V, Action::FrameView, "frame the body"),
    (Key::C, Action::ResetCamera, "reset the camera"),
    (
        Key::E,
        Action::Inspector,
        "inspector (numbers of the selected tet and particle's contacts)",
    ),
    (
        Key::D,
        Action::Modes,
        "modes (eigenvalues of the selected tet's energy)",
    ),
    (Key::L, Action::Lesson, "lessons"),
    (
        Key::G,
        Action::ConstraintEditor,
        "constraint editor (write C, check your gradient)",
    ),
    (
        Key::O,
        Action::OpenFile,
        "open a mesh, lesson or constraint file",
    ),
    (
        Key::F5,
        Action::Classroom,
        "classroom mode (large, view and lesson only)",
    ),
    (Key::ArrowRight, Action::NextStep, "lesson: next step"),
    (
        Key::ArrowLeft,
        Action::PreviousStep,
        "lesson: previous step",
    ),
    (Key::Enter, Action::DoStep, "lesson: do this step"),
    (Key::H, Action::Help, "this help"),
];
