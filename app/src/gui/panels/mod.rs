//! The workbench's panels, one file each, all with the one signature of [`Panel`]: a panel owns
//! what it edits between frames (a typed path, the families to compare, the display options, the
//! editor's text), reads what it shows from a [`Context`], and adds what the user asks for to the
//! frame's [`Request`]s, which the app carries out once every panel is drawn. A panel can so be
//! drawn, and snapshot, on its own (`tests/gui.rs`).

pub mod compare;
pub mod constraint_editor;
pub mod controls;
pub mod display;
pub mod help;
pub mod inspector;
pub mod lesson;
pub mod modes;
pub mod readouts;
pub mod solver;
pub mod tools;

use super::request::Request;
use super::workbench::Workbench;
use eframe::egui;
use lesson::LessonState;
use std::time::Duration;

/// What the panels read this frame.
pub struct Context<'a> {
    /// The simulation and its selection.
    pub bench: &'a Workbench,
    /// The second simulation, while two are compared.
    pub comparison: Option<&'a Workbench>,
    /// The lesson in progress.
    pub lesson: Option<&'a LessonState>,
    /// How long the last simulation step took.
    pub step_time: Duration,
    /// The time between the last two frames drawn.
    pub frame_time: Duration,
    /// Classroom mode: larger, for a projector.
    pub classroom: bool,
}

impl<'a> Context<'a> {
    /// The context of `bench` alone: no comparison, no lesson, no timings.
    pub fn of(bench: &'a Workbench) -> Self {
        Context {
            bench,
            comparison: None,
            lesson: None,
            step_time: Duration::ZERO,
            frame_time: Duration::ZERO,
            classroom: false,
        }
    }
}

/// A panel of the workbench.
pub trait Panel {
    /// Draws the panel into `ui` (a window draws itself over `ui`'s context), showing what
    /// `context` holds, and adds what the user asked for to `requests`.
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>);
}
