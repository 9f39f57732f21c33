//! tetlab-core: the simulation side of tetlab, with no GUI dependencies.
//!
//! - [`constraints`]: the edge-distance, height-above-face and signed-volume constraints, their
//!   values and analytic gradients, written once for f64, f32 and eight f32 lanes ([`lanes`]),
//!   and the table of families that everything else reads ([`constraints::family`]).
//! - [`finite_difference`]: numerical gradients to check the analytic ones against.
//! - [`verify`]: analytic gradients against finite differences on random configurations;
//!   [`inspector`]: the same check, live, on the constraints of one tet.
//! - [`random`]: a seeded generator, so random inputs are the same everywhere.
//! - [`vector`]: the small vector trait the formulas are generic over.
//! - [`solver`]: the XPBD/PBD simulation; [`stepper`]: the same, one projection at a time;
//!   [`fast`]: the same in f32, coloured, in SIMD lanes and on threads, for big meshes;
//!   [`projection`]: the rule by which both solvers project one constraint.
//! - [`mesh`], [`scene`]: tet meshes (TetGen, Gmsh) and the scenes built from them; [`metrics`]:
//!   what a state is worth; [`outcome`]: what a run came to; [`ensemble`]: one scene under many
//!   projection orders; [`visual`]: what front ends draw; [`lesson`]: lessons as TOML files;
//!   [`text_file`]: reading a user's text file; [`shared_meshes`]: where the reference meshes
//!   beside a clone are.
//! - [`limits`]: the range of every setting and the size of every scene tetlab accepts;
//!   [`divergence`]: when a simulation's numbers stop meaning anything, and why.

pub mod constraint_file;
pub mod constraints;
pub mod divergence;
pub mod dual;
pub mod ensemble;
pub mod fast;
pub mod finite_difference;
pub mod inspector;
mod integrate;
pub mod lanes;
pub mod lesson;
pub mod limits;
pub mod material;
pub mod mesh;
pub mod metrics;
pub mod outcome;
pub mod projection;
pub mod random;
pub mod scene;
pub mod shared_meshes;
pub mod solver;
pub mod stepper;
pub mod text_file;
pub mod validation;
pub mod vector;
pub mod verify;
pub mod visual;
