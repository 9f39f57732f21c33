//! The numbers the formulas run on: the [`vector::Vector3`] trait they are generic over, with f64,
//! f32 and eight f32 [`lanes`], and several of one type side by side in a `block`; [`dual`]
//! numbers for automatic differentiation; [`finite_difference`] gradients to check against; a
//! seeded [`random`] generator, so that random inputs are the same everywhere; and 3 × 3 matrices
//! as [`columns`], with their signed singular value and polar decompositions ([`svd3`]).

pub(crate) mod block;
pub mod columns;
pub mod dual;
pub mod finite_difference;
pub mod lanes;
pub mod random;
pub mod svd3;
pub mod traced;
pub mod vector;
