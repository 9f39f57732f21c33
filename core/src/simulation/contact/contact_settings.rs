//! How contact behaves ([`ContactSettings`]): its thickness and its friction, part of the
//! simulation's settings.

/// How contact behaves: the thickness d it keeps between surfaces, and the friction
/// coefficients.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContactSettings {
    /// The thickness d, m: a particle is held at least d above any surface triangle it meets.
    pub thickness: f64,
    /// Static friction μ_s: a contact sticks while the slide it would make is under μ_s times
    /// the push along the normal.
    pub static_friction: f64,
    /// Kinetic friction μ_k: a sliding contact is slowed by μ_k times the push.
    pub kinetic_friction: f64,
}

impl Default for ContactSettings {
    /// d = 0.01 m, μ_s = 0.5, μ_k = 0.4.
    fn default() -> Self {
        ContactSettings {
            thickness: 0.01,
            static_friction: 0.5,
            kinetic_friction: 0.4,
        }
    }
}

impl ContactSettings {
    /// Ok when the thickness is positive and finite and the coefficients are in [0, 10];
    /// otherwise what is wrong, named.
    pub fn check(&self) -> Result<(), String> {
        crate::input::limits::THICKNESS.check(self.thickness)?;
        crate::input::limits::FRICTION
            .check(self.static_friction)
            .map_err(|e| format!("static {e}"))?;
        crate::input::limits::FRICTION
            .check(self.kinetic_friction)
            .map_err(|e| format!("kinetic {e}"))?;
        Ok(())
    }
}
