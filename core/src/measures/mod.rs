//! What a run is worth: [`metrics`] of one state, the [`outcome`] a run comes to, the same scene
//! under many projection orders ([`ensemble`]), and the engines against theory ([`validation`]).

pub mod ensemble;
pub mod metrics;
pub mod outcome;
pub mod validation;
