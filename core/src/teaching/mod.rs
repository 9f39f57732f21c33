//! What a learner sees and does: [`visual`] (what every front end draws, from the simulation),
//! [`stepper`] (one projection at a time), [`inspector`] (the live gradient check of one tet,
//! by [`crate::constraints::verify`]) and [`lesson`]s as TOML files.

pub mod inspector;
pub mod lesson;
pub mod stepper;
pub mod visual;
