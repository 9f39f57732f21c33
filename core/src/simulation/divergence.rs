//! When a simulation's numbers stop meaning anything, and why. A position or velocity beyond
//! what its engine can hold ([`crate::simulation::SOUND_LIMIT`] in f64; in f32 positions only up to
//! [`crate::simulation::fast::POSITION_LIMIT`]), or a metric that is not finite, is a divergence. Every
//! front end checks after each frame ([`crate::simulation::Simulation::check`],
//! [`crate::simulation::fast::FastSimulation::check`], [`crate::measures::metrics::Metrics::measure_sound`]) and stops
//! with this message rather than print, draw or record a number that is not one.
//!
//! The input limits of [`crate::input::limits`] keep every accepted setting and mesh from leaving that
//! range by itself (a free fall included), so a divergence is a real instability, and the advice
//! is the one that helps with that: more substeps or a shorter frame.

use std::fmt;

/// What left the sound range.
#[derive(Clone, Debug, PartialEq)]
pub enum Cause {
    /// A coordinate of a particle reached `value` (metres), beyond `limit` or not a number.
    Position {
        /// The particle, in the scene's numbering.
        particle: usize,
        /// The coordinate.
        value: f64,
        /// The engine's limit.
        limit: f64,
    },
    /// A velocity component of a particle reached `value` (m/s), beyond `limit` or not a number.
    Velocity {
        /// The particle, in the scene's numbering.
        particle: usize,
        /// The component.
        value: f64,
        /// The engine's limit.
        limit: f64,
    },
    /// A metric of the state is not finite.
    Metric {
        /// Its name, as in [`crate::measures::metrics::Metrics::headline`].
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// The RMS residual of a family is not finite.
    Residual {
        /// The family's name.
        family: String,
        /// Its value.
        value: f64,
    },
}

/// A simulation that diverged: which one, at which frame, and what left the range.
#[derive(Clone, Debug, PartialEq)]
pub struct Divergence {
    /// What the message calls the simulation: "the simulation", "the comparison".
    pub subject: &'static str,
    /// The frame at which it was found.
    pub frame: u64,
    /// What left the range.
    pub cause: Cause,
}

impl Divergence {
    /// A divergence of "the simulation".
    pub fn new(frame: u64, cause: Cause) -> Divergence {
        Divergence {
            subject: "the simulation",
            frame,
            cause,
        }
    }

    /// The same, of another simulation (e.g. "the comparison").
    pub fn of(self, subject: &'static str) -> Divergence {
        Divergence { subject, ..self }
    }

    /// The first coordinate of `positions` not below `limits.0` in size, or else the first
    /// velocity component of `velocities` not below `limits.1` (particle `i` is `particle(i)` in
    /// the scene's numbering), as a divergence at `frame`.
    pub fn find(
        frame: u64,
        limits: (f64, f64),
        positions: impl Iterator<Item = [f64; 3]>,
        velocities: impl Iterator<Item = [f64; 3]>,
        particle: impl Fn(usize) -> usize,
    ) -> Result<(), Divergence> {
        // The first component not below the limit (beyond it, or NaN), with its particle.
        let first = |values: &mut dyn Iterator<Item = [f64; 3]>, limit: f64| {
            values.enumerate().find_map(|(i, v)| {
                v.into_iter()
                    .find(|x| x.abs().partial_cmp(&limit) != Some(std::cmp::Ordering::Less))
                    .map(|value| (particle(i), value))
            })
        };
        let (mut positions, mut velocities) = (positions, velocities);
        if let Some((particle, value)) = first(&mut positions, limits.0) {
            let limit = limits.0;
            let cause = Cause::Position {
                particle,
                value,
                limit,
            };
            return Err(Divergence::new(frame, cause));
        }
        if let Some((particle, value)) = first(&mut velocities, limits.1) {
            let limit = limits.1;
            let cause = Cause::Velocity {
                particle,
                value,
                limit,
            };
            return Err(Divergence::new(frame, cause));
        }
        Ok(())
    }
}

impl fmt::Display for Divergence {
    /// `the simulation diverged at frame 12: a velocity of particle 3 reached 2e30 m/s (the
    /// engine holds up to 1e30); more substeps or a shorter frame (dt) may keep it stable`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} diverged at frame {}: ", self.subject, self.frame)?;
        let number = |x: &f64| {
            let x = *x;
            if x.is_finite() {
                format!("{x:.3e}")
            } else {
                x.to_string()
            }
        };
        match &self.cause {
            Cause::Position {
                particle,
                value,
                limit,
            } => write!(
                f,
                "a coordinate of particle {particle} reached {} m (the engine holds up to {limit:e})",
                number(value)
            )?,
            Cause::Velocity {
                particle,
                value,
                limit,
            } => write!(
                f,
                "a velocity of particle {particle} reached {} m/s (the engine holds up to {limit:e})",
                number(value)
            )?,
            Cause::Metric { name, value } => write!(f, "{name} became {}", number(value))?,
            Cause::Residual { family, value } => write!(
                f,
                "the RMS residual of the {family} constraints became {}",
                number(value)
            )?,
        }
        f.write_str("; more substeps or a shorter frame (dt) may keep it stable")
    }
}

impl std::error::Error for Divergence {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_value_out_of_range_is_named() {
        let positions = [[0.0, 1.0, 2.0], [0.0, f64::NAN, 0.0]];
        let velocities = [[0.0; 3], [3e30, 0.0, 0.0]];
        let found = Divergence::find(
            7,
            (1e30, 1e30),
            positions.into_iter(),
            velocities.into_iter(),
            |i| i + 10,
        )
        .unwrap_err();
        assert!(matches!(
            found.cause,
            Cause::Position { particle: 11, value, .. } if value.is_nan()
        ));
        let text = found.of("the comparison").to_string();
        assert!(
            text.starts_with(
                "the comparison diverged at frame 7: a coordinate of particle 11 reached NaN m"
            ),
            "{text}"
        );
        let fine = Divergence::find(
            0,
            (1e30, 1e30),
            positions[..1].iter().copied(),
            [[0.0; 3]].into_iter(),
            |i| i,
        );
        assert_eq!(fine, Ok(()));
    }
}
