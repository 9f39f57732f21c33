//! A material in physical units: Young's modulus E (Pa) and Poisson's ratio ν, and the
//! parameters the neo-Hookean constraints take from them.
//!
//! # Formula
//! The Lamé parameters of linear elasticity are
//!
//! μ = E / (2 (1 + ν)),   λ_L = E ν / ((1 + ν)(1 − 2ν)).
//!
//! The stable neo-Hookean energy without its log term, Ψ = μ/2 (tr FᵀF − 3) + λ/2 (det F − γ)²
//! with γ = 1 + μ/λ, linearises at F = I to μ tr ε² + (λ − μ)/2 (tr ε)² (docs/gradients.md). So
//! that small deformations follow linear elasticity with E and ν, the constraints take
//!
//! μ as it is, λ = λ_L + μ, γ = 1 + μ/λ,
//!
//! and their compliances are 1/μ (deviatoric) and 1/λ (hydrostatic), per unit rest volume.
//! λ stays positive for ν = 0, where λ_L is zero.
//!
//! ```
//! use tetlab_core::constraints::material::Material;
//! let rubber = Material::parse("E=1e6,nu=0.25").unwrap();
//! assert_eq!(rubber.mu(), 4e5);
//! assert!((rubber.lambda() - (4e5 + 4e5)).abs() < 1e-6); // λ_L = 4e5 at ν = 1/4
//! assert!((rubber.gamma() - 1.5).abs() < 1e-12);
//! assert!(Material::parse("E=1e6,nu=0.5").unwrap_err().contains("nu"));
//! ```

use crate::input::limits::{Bounds, Number};

/// Young's modulus in Pa: from jelly (10⁻³) to above diamond (10¹³). Its compliance 1/μ stays
/// within [`crate::input::limits::COMPLIANCE`].
pub const YOUNG: Bounds<f64> = Bounds {
    name: "E",
    min: 1e-3,
    max: 1e13,
};

/// The largest Poisson's ratio accepted: at 0.5 the material is incompressible and λ infinite.
/// Just below, λ/μ is 10⁵.
pub const MAX_POISSON: f64 = 0.499_99;

/// The largest c h / L at which the neo-Hookean pair was stable on the cube
/// (`tetlab run --scene cube --constraints neohookean --material E=1e8,nu=0.3 --substeps 24`
/// and `E=1e9 --substeps 80`: stable at 1.02 and 0.97, unstable at 1.22 and 1.29).
pub const STABLE_COURANT: f64 = 1.0;

/// An isotropic elastic material.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    /// Young's modulus E in Pa.
    pub young: f64,
    /// Poisson's ratio ν, 0 ≤ ν < 0.5.
    pub poisson: f64,
}

impl Default for Material {
    /// A soft rubber: E = 1 MPa, ν = 0.3. A 1 m body of density 1000 kg/m³ sags about 1 % under
    /// its own weight.
    fn default() -> Self {
        Material {
            young: 1e6,
            poisson: 0.3,
        }
    }
}

impl Material {
    /// The shear modulus μ = E / (2 (1 + ν)).
    pub fn mu(&self) -> f64 {
        self.young / (2.0 * (1.0 + self.poisson))
    }

    /// The hydrostatic constraint's λ = λ_L + μ, with λ_L = E ν / ((1 + ν)(1 − 2ν)) the Lamé
    /// parameter of linear elasticity.
    pub fn lambda(&self) -> f64 {
        let nu = self.poisson;
        self.young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)) + self.mu()
    }

    /// γ = 1 + μ/λ: the det F the hydrostatic constraint aims at, so that the rest shape is in
    /// equilibrium (the deviatoric constraint pulls inwards at F = I).
    pub fn gamma(&self) -> f64 {
        1.0 + self.mu() / self.lambda()
    }

    /// The speed of pressure waves, c = √((λ_L + 2μ) / ρ), in m/s at density `density`.
    pub fn wave_speed(&self, density: f64) -> f64 {
        let nu = self.poisson;
        let p_modulus = self.young * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        (p_modulus / density).sqrt()
    }

    /// The fewest substeps per frame of length `dt` that keep the neo-Hookean pair stable on a
    /// mesh whose shortest edge is `shortest_edge`: a substep h must satisfy c h ≤
    /// [`STABLE_COURANT`] × shortest edge. The pair pulls against itself at rest with a force
    /// that grows with μ, and the solver, which linearises each constraint, overshoots when a
    /// wave crosses more than a cell in a substep (docs/experiments.md).
    pub fn substeps_needed(&self, dt: f64, shortest_edge: f64, density: f64) -> u64 {
        let h = STABLE_COURANT * shortest_edge / self.wave_speed(density);
        let needed = (dt / h).ceil();
        if needed.is_finite() && needed >= 1.0 {
            needed.min(u64::MAX as f64) as u64
        } else {
            1
        }
    }

    /// Ok when E and ν are in range; otherwise the first that is not, named.
    pub fn check(&self) -> Result<(), String> {
        YOUNG.check(self.young)?;
        let nu = self.poisson;
        if nu.is_nan() {
            return Err("nu NaN is not a number".into());
        }
        if !(0.0..=MAX_POISSON).contains(&nu) {
            return Err(format!(
                "nu {} is out of range: expected 0 <= nu < 0.5 (at most {MAX_POISSON})",
                nu.show()
            ));
        }
        Ok(())
    }

    /// `E=PA,nu=N` (in either order, spaces allowed), both required and checked.
    pub fn parse(text: &str) -> Result<Material, String> {
        let (mut young, mut poisson) = (None, None);
        for part in text.split(',') {
            let (key, value) = part
                .split_once('=')
                .ok_or_else(|| format!("'{}' is not KEY=VALUE (E=1e6,nu=0.3)", part.trim()))?;
            let number = |name: &str| {
                value
                    .trim()
                    .parse::<f64>()
                    .map_err(|_| format!("{name}: '{}' is not a number", value.trim()))
            };
            match key.trim() {
                "E" => young = Some(number("E")?),
                "nu" => poisson = Some(number("nu")?),
                other => {
                    return Err(format!(
                        "unknown material parameter '{other}': expected E (Pa) and nu"
                    ));
                }
            }
        }
        let material = Material {
            young: young.ok_or("E is missing: give E=PA,nu=N (e.g. E=1e6,nu=0.3)")?,
            poisson: poisson.ok_or("nu is missing: give E=PA,nu=N (e.g. E=1e6,nu=0.3)")?,
        };
        material.check()?;
        Ok(material)
    }

    /// `E=1000000,nu=0.3`, as [`Material::parse`] reads it.
    pub fn describe(&self) -> String {
        format!("E={},nu={}", self.young.show(), self.poisson.show())
    }
}
