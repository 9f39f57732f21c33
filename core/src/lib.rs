//! tetlab-core: the simulation side of tetlab, with no GUI dependencies. Its folders stack in
//! layers; each uses only those above it in this list:
//!
//! - [`numbers`]: the vector trait the formulas are generic over, f64, f32 and SIMD [`lanes`],
//!   dual numbers, finite differences and a seeded generator;
//! - [`input`]: reading a user's text files, where the reference meshes are, and the range of
//!   every number a user may set;
//! - [`constraints`]: every constraint family (edges, heights, volume, the neo-Hookean pair and
//!   those of constraint files), its formula and gradient written once, the table of families,
//!   and materials;
//! - [`constraint_file`]: constraints a user writes as a file, compiled to a tape and checked;
//! - [`scene`]: tet meshes and their formats (TetGen, Gmsh), and the scenes built from them;
//! - [`simulation`]: the XPBD/PBD simulation every front end drives, on its reference (f64) and
//!   fast (f32, SIMD, threads) solvers, with the projection rule both share;
//! - [`energy`]: a family's energy on one tet, its Hessian by automatic differentiation, checked,
//!   and its eigenmodes, with the neo-Hookean energy's analytic eigensystem;
//! - [`measures`]: what a state is worth, what a run came to, one scene under many orders, and
//!   the engines against theory;
//! - [`teaching`]: what front ends draw, step-by-step projection, the live inspector, the
//!   gradient check and lessons.
//!
//! [`lanes`]: numbers::lanes

pub mod constraint_file;
pub mod constraints;
pub mod energy;
pub mod input;
pub mod measures;
pub mod numbers;
pub mod scene;
pub mod simulation;
pub mod teaching;
