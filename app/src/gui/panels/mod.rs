//! The side panels of the workbench, one file each.

pub mod compare;
pub mod constraint_editor;
pub mod controls;
pub mod display;
pub mod help;
pub mod inspector;
pub mod lesson;
pub mod readouts;
pub mod solver;
pub mod tools;
