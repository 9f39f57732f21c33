//! tetlab-core: the simulation side of tetlab, with no GUI dependencies. Its folders stack in
//! layers; each uses only those above it in this list:
//!
//! - [`numbers`]: the vector trait the formulas are generic over, f64, f32 and SIMD [`lanes`],
//!   dual numbers, finite differences and a seeded generator;
//! - [`input`]: reading a user's text files, where the reference meshes are, and the range of
//!   every number a user may set;
//! - [`constraints`]: every constraint family (edges, heights, volume, the neo-Hookean pair and
//!   those of constraint files): its formula and gradient written once, what it is as data (its
//!   row), the table of families, the one dispatch to a family's type, and materials;
//! - [`constraint_file`]: constraints a user writes as a file, compiled to a tape and checked;
//! - [`scene`]: tet meshes and their formats (TetGen, Gmsh), and the scenes built from them;
//! - [`simulation`]: the XPBD/PBD simulation every front end drives: it owns its settings, body
//!   and state, and an engine steps them through one interface, the reference engine (f64) or
//!   the fast one (f32, SIMD, threads), both on one substep and one projection rule;
//! - [`energy`]: a family's energy on one tet, its Hessian by automatic differentiation, checked,
//!   and its eigenmodes, with the neo-Hookean energy's analytic eigensystem;
//! - [`measures`]: what a state is worth, what a run came to, one scene under many orders, and
//!   the engines against theory;
//! - [`teaching`]: what front ends draw, step-by-step projection, the live inspector, the
//!   gradient check and lessons.
//!
//! [`lanes`]: numbers::lanes

#![warn(unreachable_pub)]

pub mod constraint_file;
pub mod constraints;
pub mod energy;
pub mod input;
pub mod measures;
pub mod numbers;
pub mod scene;
pub mod simulation;
pub mod teaching;
