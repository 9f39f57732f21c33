//! What a constraint's energy does on one tet: the energy of a family (or of several) on the tet
//! ([`element::ElementEnergy`]), its Hessian by automatic differentiation and the checks of it
//! ([`hessian`]), the Hessian's eigenmodes, classified, projected and mass-weighted ([`modes`]),
//! and the analytic eigensystem of the neo-Hookean energy in F-space ([`neohookean`]), both
//! written in the frame of F's signed SVD ([`svd`]). The Hessian of one constraint, ∇²C, is
//! checked like its gradient in [`check`].
//!
//! # Formula
//! A family's XPBD potential on a tet is the sum over its constraints there of
//!
//! E = ½ C² / α,
//!
//! α the family's compliance. A rigid family (α = 0) has no finite energy; it is taken with α = 1,
//! and said so ([`element::Compliance::Rigid`]): compare such families by the signs and shapes
//! of their eigenvalues, not their sizes. The neo-Hookean pair's compliances are 1/μ and 1/λ per
//! unit rest volume, its constraints scaled by s = √|V₀|, so that its E is the material's energy
//! |V₀| Ψ(F), Ψ = μ/2 ‖F‖²_F + λ/2 (det F − γ)² ([`neohookean`]).
//!
//! Its Hessian with respect to the tet's 12 coordinates is
//!
//! H = Σ (∇C ∇Cᵀ + C ∇²C) / α.
//!
//! Where every C = 0 the second term vanishes, and H has the rank of the constraints' gradients:
//! a tet's volume leaves 11 zero eigenvalues, its four heights 8, its six edges 6.
//!
//! ```
//! use glam::DVec3;
//! use tetlab_core::constraints::Families;
//! use tetlab_core::energy::element::ElementEnergy;
//! use tetlab_core::energy::modes::Modes;
//! use tetlab_core::simulation::Settings;
//! let families = Families::builtin();
//! let rest = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
//! let active = families.parse_list("volume").unwrap();
//! let energy = ElementEnergy::new(&families, &active, &Settings::default(), rest).unwrap();
//! // At rest, C = 0: one constraint, one non-zero eigenvalue, eleven zero ones.
//! let modes = Modes::of(&energy, &rest);
//! assert_eq!(modes.zero_count(), 11);
//! assert!(modes.values()[11] > 0.0);
//! ```

pub mod check;
pub mod element;
pub mod hessian;
pub mod modes;
pub mod neohookean;
pub mod svd;
