//! What tetlab accepts: the range of every setting, the size of a scene and the coordinates of a
//! mesh, in one place, with the reason each limit is where it is. The command line, lesson files
//! and the workbench all check their input here, so the same value is refused everywhere with
//! the same words, before it reaches the solver.
//!
//! The limits are chosen so that no accepted input can overflow inside either engine:
//! - a frame is at least [`DT`]'s 10⁻⁶ s and a substep at least 10⁻⁶ / 1000 s, so
//!   α̃ = α / h² ≤ [`COMPLIANCE`]'s 10¹⁰ / 10⁻¹⁸ = 10²⁸ stays finite even in f32 (10³⁸);
//! - coordinates of a mesh are at most [`MAX_COORDINATE`] = 10⁶ m in size, so an edge is at most
//!   about 3.5·10⁶ and the fourth power of an edge (the squared volume gradient the projection
//!   divides by) stays below 10²⁷, far from f32's 3.4·10³⁸;
//! - gravity is at most 10⁶ m/s² and a run at most 10⁷ frames of at most 1 s, so a body in free
//!   fall moves at most ½ · 10⁶ · (10⁷)² = 5·10¹⁹ m, below the f64 engine's
//!   [`SOUND_LIMIT`] of 10³⁰: leaving that range is always a real divergence;
//! - at most [`MAX_TETS`] tets, so that a scene fits in memory (the reference solver keeps about
//!   300 bytes per tet) and its indices in 32 bits.
//!
//! ```
//! use tetlab_core::input::limits::{COMPLIANCE, DT};
//! assert_eq!(DT.parse("0.01"), Ok(0.01));
//! assert!(DT.parse("1e-320").unwrap_err().contains("out of range"));
//! assert!(COMPLIANCE.check(f64::NAN).unwrap_err().contains("not a number"));
//! ```

use std::fmt;
use std::str::FromStr;

/// A number a setting can be: it can be parsed, compared and shown in a message.
pub trait Number: Copy + PartialOrd + FromStr {
    /// The number as a message shows it: short, in scientific notation when that is shorter.
    fn show(self) -> String;
    /// What a word must look like to be one ("a number", "a whole number").
    const KIND: &'static str;
}

impl Number for f64 {
    fn show(self) -> String {
        let plain = self.to_string();
        let scientific = format!("{self:e}");
        if plain.len() <= scientific.len() {
            plain
        } else {
            scientific
        }
    }
    const KIND: &'static str = "a number";
}

macro_rules! whole_number {
    ($($t:ty),*) => {$(
        impl Number for $t {
            fn show(self) -> String {
                self.to_string()
            }
            const KIND: &'static str = "a whole number";
        }
    )*};
}
whole_number!(u32, u64, usize);

/// The closed range [min, max] a setting must lie in, and the name messages call it by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds<T> {
    /// The setting's name in messages: `dt`, `compliance`, …
    pub name: &'static str,
    /// The smallest accepted value.
    pub min: T,
    /// The largest accepted value.
    pub max: T,
}

impl<T: Number> Bounds<T> {
    /// Whether min ≤ `value` ≤ max (never for NaN).
    pub fn contains(&self, value: T) -> bool {
        self.min <= value && value <= self.max
    }

    /// The range as a message shows it: `1e-6 <= dt <= 1`.
    pub fn describe(&self) -> String {
        format!(
            "{} <= {} <= {}",
            self.min.show(),
            self.name,
            self.max.show()
        )
    }

    /// `value` when it lies in the range; otherwise why not, naming the setting:
    /// `dt 0 is out of range: expected 1e-6 <= dt <= 1`, `compliance NaN is not a number`.
    pub fn check(&self, value: T) -> Result<T, String> {
        if value.partial_cmp(&value).is_none() {
            return Err(format!("{} NaN is not a number", self.name));
        }
        if self.contains(value) {
            Ok(value)
        } else {
            Err(format!(
                "{} {} is out of range: expected {}",
                self.name,
                value.show(),
                self.describe()
            ))
        }
    }

    /// The value written in `text` (spaces around it allowed), checked.
    pub fn parse(&self, text: &str) -> Result<T, String> {
        let value: T = text
            .trim()
            .parse()
            .map_err(|_| format!("{}: '{}' is not {}", self.name, text.trim(), T::KIND))?;
        self.check(value)
    }
}

impl<T: Number> fmt::Display for Bounds<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.describe())
    }
}

/// Substeps per frame.
pub const SUBSTEPS: Bounds<u32> = Bounds {
    name: "substeps",
    min: 1,
    max: 1000,
};

/// Gauss–Seidel sweeps per substep.
pub const ITERATIONS: Bounds<u32> = Bounds {
    name: "iterations",
    min: 1,
    max: 1000,
};

/// The frame length Δt in seconds. Below 10⁻⁶ s, h² of a substep nears the bottom of f32 and
/// α / h² the top.
pub const DT: Bounds<f64> = Bounds {
    name: "dt",
    min: 1e-6,
    max: 1.0,
};

/// Gravity along −y in m/s² (negative pulls up). 10⁶ is 10⁵ times the Earth's.
pub const GRAVITY: Bounds<f64> = Bounds {
    name: "gravity",
    min: -1e6,
    max: 1e6,
};

/// XPBD compliance α of a family (and of the grab). Already at 10 a family barely resists; 10¹⁰
/// keeps α / h² finite in f32 for every accepted h.
pub const COMPLIANCE: Bounds<f64> = Bounds {
    name: "compliance",
    min: 0.0,
    max: 1e10,
};

/// PBD stiffness k of a family.
pub const STIFFNESS: Bounds<f64> = Bounds {
    name: "stiffness",
    min: 0.0,
    max: 1.0,
};

/// Velocity damping per second; at 10⁶ every substep stops the body.
pub const DAMPING: Bounds<f64> = Bounds {
    name: "damping",
    min: 0.0,
    max: 1e6,
};

/// How far one projection may move a particle, in longest rest edges of its element
/// ([`crate::simulation::Settings::reach`]). Below 1 a body could not even be mirrored back.
pub const REACH: Bounds<f64> = Bounds {
    name: "reach",
    min: 1.0,
    max: 1e9,
};

/// The thickness contact keeps between surfaces, m
/// ([`crate::simulation::contact::ContactSettings::thickness`]): positive, since a contact
/// of thickness 0 would lose the particle resting on it to rounding.
pub const THICKNESS: Bounds<f64> = Bounds {
    name: "thickness",
    min: 1e-9,
    max: 1e3,
};

/// A coefficient of friction, static or kinetic
/// ([`crate::simulation::contact::ContactSettings`]).
pub const FRICTION: Bounds<f64> = Bounds {
    name: "friction",
    min: 0.0,
    max: 10.0,
};

/// A body's density in kg/m³ (a scene file's `density`): from well below cork (10) to above
/// osmium (22 590); the default is [`crate::simulation::DENSITY`].
pub const DENSITY: Bounds<f64> = Bounds {
    name: "density",
    min: 1.0,
    max: 1e5,
};

/// Frames a headless run simulates.
pub const FRAMES: Bounds<u64> = Bounds {
    name: "frames",
    min: 0,
    max: 10_000_000,
};

/// Members of an ensemble: runs of one scene under different projection orders
/// ([`crate::measures::ensemble`]).
pub const ENSEMBLE: Bounds<u64> = Bounds {
    name: "ensemble",
    min: 1,
    max: 1024,
};

/// The resolution of a built-in scene (cells along a side); the scene must also stay within
/// [`MAX_TETS`].
pub const RESOLUTION: Bounds<u32> = Bounds {
    name: "resolution",
    min: 1,
    max: 128,
};

/// The largest size of a mesh coordinate, in metres: see the module documentation.
pub const MAX_COORDINATE: f64 = 1e6;

/// The most tets a scene may have (2²⁴ = 16 777 216, a cube of resolution 128 and more).
pub const MAX_TETS: usize = 1 << 24;

/// The largest coordinate or velocity component (in m or m/s) a sound simulation in f64 has:
/// below it, volumes (cubes), squared residuals and their sums over any mesh stay finite.
pub const SOUND_LIMIT: f64 = 1e30;

/// A coordinate of a mesh, if its size is at most [`MAX_COORDINATE`]; otherwise why not.
pub fn coordinate(value: f64) -> Result<f64, String> {
    if value.abs() <= MAX_COORDINATE {
        Ok(value)
    } else {
        Err(format!(
            "{} is beyond ±{}, the largest coordinate tetlab simulates (its f32 engine raises \
             lengths to the fourth power); scale the mesh down",
            value.show(),
            MAX_COORDINATE.show()
        ))
    }
}

/// A count of tets, if it is at most [`MAX_TETS`]; otherwise why not.
pub fn tet_count(count: usize) -> Result<usize, String> {
    if count <= MAX_TETS {
        Ok(count)
    } else {
        Err(format!(
            "{count} tets are more than the {MAX_TETS} tetlab simulates"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_setting_and_the_range() {
        assert_eq!(
            DT.parse("0").unwrap_err(),
            "dt 0 is out of range: expected 1e-6 <= dt <= 1"
        );
        assert_eq!(
            COMPLIANCE.parse("inf").unwrap_err(),
            "compliance inf is out of range: expected 0 <= compliance <= 1e10"
        );
        assert_eq!(
            COMPLIANCE.parse("nan").unwrap_err(),
            "compliance NaN is not a number"
        );
        assert_eq!(
            SUBSTEPS.parse("-1").unwrap_err(),
            "substeps: '-1' is not a whole number"
        );
        assert_eq!(SUBSTEPS.parse(" 12 "), Ok(12));
        assert_eq!(GRAVITY.parse("-9.81"), Ok(-9.81));
        assert!(coordinate(-1e6).is_ok() && coordinate(1e31).is_err());
        assert!(tet_count(MAX_TETS).is_ok() && tet_count(MAX_TETS + 1).is_err());
    }

    #[test]
    fn no_accepted_setting_overflows_the_projection_rule_in_f32() {
        let smallest_substep = DT.min / SUBSTEPS.max as f64;
        let alpha_tilde = COMPLIANCE.max / (smallest_substep * smallest_substep);
        assert!(alpha_tilde < f32::MAX as f64 * 1e-6, "{alpha_tilde}");
        let longest_edge = 2.0 * 3f64.sqrt() * MAX_COORDINATE;
        assert!(longest_edge.powi(4) < f32::MAX as f64 * 1e-6);
        let fall = 0.5 * GRAVITY.max * (FRAMES.max as f64 * DT.max).powi(2);
        assert!(fall < SOUND_LIMIT * 1e-6, "{fall}");
    }
}
