//! What a run is worth: [`metrics`] of one state, the [`outcome`] a run comes to, the same scene
//! under many projection orders ([`ensemble`]), the engines against theory ([`validation`]),
//! where a body's energy is ([`energy_account`]), and how far a frame is from the exact one
//! ([`exact_step`]).

pub mod energy_account;
pub mod ensemble;
pub mod exact_step;
pub mod metrics;
pub mod outcome;
pub mod validation;
