//! The energy account of a state ([`Energy`]) and of a run ([`EnergyWatch`]): where a body's
//! energy is, frame by frame, and the frame where it grew.
//!
//! # Formula
//! E = K + U_g + U_f + Σ_families U_c, with
//! - K = Σᵢ ½ mᵢ |vᵢ|², the kinetic energy of the free particles (held ones have no mass here);
//! - U_g = Σᵢ mᵢ g yᵢ, gravity's, above the ground's height y = 0;
//! - U_f = −Σᵢ fᵢ·(xᵢ − x⁰ᵢ), the constant external forces', zero at the rest shape;
//! - U_c = Σ_c ½ (C_c(x)² − C_c(x⁰)²) / α for each active compliant family: the energy XPBD's
//!   compliance stands for (the material's, for the neo-Hookean pair), zero at the rest shape
//!   (the pair is pre-stressed: its terms do not vanish there, their sum's gradient does).
//!
//! A rigid family (α = 0) stores no energy: what it holds it holds exactly, and a start that
//! violates it (a mirrored body under rigid edges) has a store the account cannot see, released
//! as motion and height while the violation is undone. The account measures that violation
//! ([`Energy::violation`]) and books a rise of E in a frame that began with a rigid family
//! violated as that release, not as a gain: the account judges energy while the rigid families
//! hold. Damping, the ground's sticking and XPBD's
//! own dissipation take energy; nothing else gives any. So beyond such a release E never grows,
//! less rounding: [`EnergyWatch`] says where it does.

use crate::constraints::differentiable::of_constraint;
use crate::constraints::{Family, PerFamily};
use crate::simulation::Simulation;
use glam::DVec3;

/// The energy of one state, J.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Energy {
    /// Σ ½ m |v|² over the free particles.
    pub kinetic: f64,
    /// Σ m g y over the free particles: above the ground's height.
    pub gravitational: f64,
    /// −Σ f·(x − x⁰): the external forces', zero at the rest shape.
    pub external: f64,
    /// Σ ½ (C² − C⁰²) / α of each active compliant family (0 for the others).
    #[serde(skip)]
    pub elastic: PerFamily<f64>,
    /// The sum of them all.
    pub total: f64,
    /// Of each active rigid family, how far it is from holding: the largest and the sum of
    /// |C| over its constraints, each relative to its element's size ((0, 0) for the others).
    /// Not energy: a rigid family has none to measure.
    #[serde(skip)]
    pub violation: PerFamily<(f64, f64)>,
}

/// A rigid family counts as violated, and a rise of the energy while it is as a release of what
/// it held, above this violation (0.1 % of an element's size).
pub const VIOLATED: f64 = 1e-3;

impl Energy {
    /// The energy of `simulation`'s state.
    ///
    /// ```
    /// use tetlab_core::measures::energy_account::Energy;
    /// use tetlab_core::scene::{Builtin, Scene};
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
    /// let simulation = Simulation::new(&scene, Settings::default());
    /// // At rest at its rest shape a body has only its weight's height.
    /// let energy = Energy::measure(&simulation);
    /// assert_eq!((energy.kinetic, energy.external), (0.0, 0.0));
    /// assert!(energy.gravitational > 0.0 && energy.total == energy.gravitational);
    /// ```
    pub fn measure(simulation: &Simulation) -> Energy {
        let body = simulation.body();
        let gravity = simulation.settings().gravity;
        let (mut kinetic, mut gravitational, mut external) = (0.0, 0.0, 0.0);
        let positions = simulation.positions();
        for (i, (&w, v)) in (simulation.inverse_masses().iter())
            .zip(simulation.velocities())
            .enumerate()
        {
            if w <= 0.0 {
                continue;
            }
            let mass = 1.0 / body.lumped_inverse_masses[i];
            kinetic += 0.5 * mass * v.length_squared();
            gravitational += mass * gravity * positions[i].y;
            if let Some(f) = body.forces.get(i) {
                external -= f.dot(positions[i] - body.rest_positions[i]);
            }
        }
        let elastic = simulation.families().per_family(|family| {
            let compliance = simulation.resolved().compliance[family];
            if !simulation.active()[family] || compliance <= 0.0 {
                return 0.0;
            }
            let now = squared_values(simulation, family, positions);
            let rest = squared_values(simulation, family, &body.rest_positions);
            0.5 * (now - rest) / compliance
        });
        let violation = simulation.families().per_family(|family| {
            let rigid = simulation.resolved().compliance[family] <= 0.0;
            if !simulation.active()[family] || !rigid {
                return (0.0, 0.0);
            }
            violation(simulation, family, positions)
        });
        let elastic_sum: f64 = simulation.families().all().map(|f| elastic[f]).sum();
        Energy {
            kinetic,
            gravitational,
            external,
            total: kinetic + gravitational + external + elastic_sum,
            elastic,
            violation,
        }
    }
}

/// Σ_c C_c(x)² over `family`'s constraints at positions `x` (a C that is not finite left out).
fn squared_values(simulation: &Simulation, family: Family, x: &[DVec3]) -> f64 {
    values(simulation, family, x)
        .map(|(c, _)| if c.is_finite() { c * c } else { 0.0 })
        .sum()
}

/// max_c and Σ_c of |C_c(x)| / size_c over `family`'s constraints at positions `x`.
fn violation(simulation: &Simulation, family: Family, x: &[DVec3]) -> (f64, f64) {
    values(simulation, family, x)
        .map(|(c, size)| (c / size.max(f64::MIN_POSITIVE)).abs())
        .filter(|v| v.is_finite())
        .fold((0.0, 0.0), |(largest, sum), v| (largest.max(v), sum + v))
}

/// C of each of `family`'s constraints at positions `x`, with its element's size.
fn values<'a>(
    simulation: &'a Simulation,
    family: Family,
    x: &'a [DVec3],
) -> impl Iterator<Item = (f64, f64)> + 'a {
    let body = simulation.body();
    let set = &body.sets[family];
    (0..set.len()).map(move |c| {
        let rest = (set.rest()[c], set.stored(c));
        let particles = set.particles(c);
        let value = of_constraint(
            simulation.families(),
            family,
            particles,
            rest,
            x,
            &body.rest_positions,
        )
        .0;
        (value, set.size()[c])
    })
}

/// Where a run's energy grew past the bound: the frame, by how much (J), and what grew most in
/// that frame (a family's name, or "kinetic", "gravitational", "external").
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Gain {
    /// The frame at whose end the total was highest above its lowest before.
    pub frame: u64,
    /// The total at that frame less the lowest total before it, J.
    pub amount: f64,
    /// What rose most over that frame.
    pub from: String,
}

/// A run's energy, frame by frame: the lowest total so far, and the largest rise above it.
///
/// A run that only loses energy never rises above its lowest total. The bound a rise is held to
/// is [`EnergyWatch::TOLERANCE`] of the run's scale: the start's kinetic, elastic and external
/// energy plus its weight times its height above the ground and the body's size (what it could
/// give back at most), so that rounding in the sums is never a gain.
#[derive(Clone, Debug)]
pub struct EnergyWatch {
    lowest: f64,
    scale: f64,
    last: Energy,
    /// The largest rise above the lowest total before it, once it passed the bound.
    pub gain: Option<Gain>,
    /// What rigid families released so far (J): the rises of frames that began with a rigid
    /// family violated (beyond [`VIOLATED`]).
    pub released: f64,
}

impl EnergyWatch {
    /// The fraction of the run's scale a rise may reach before it counts: 1 %.
    pub const TOLERANCE: f64 = 0.01;

    /// A watch from `simulation`'s state now (frame 0).
    pub fn start(simulation: &Simulation) -> EnergyWatch {
        let energy = Energy::measure(simulation);
        let body = simulation.body();
        let size = body.rest_diagonal();
        let weight: f64 = (simulation.inverse_masses().iter())
            .zip(&body.lumped_inverse_masses)
            .filter(|(w, _)| **w > 0.0)
            .map(|(_, lumped)| simulation.settings().gravity.abs() / lumped)
            .sum();
        let elastic: f64 = simulation.families().all().map(|f| energy.elastic[f]).sum();
        let scale = energy.kinetic
            + elastic.abs()
            + energy.external.abs()
            + energy.gravitational.abs()
            + weight * size;
        EnergyWatch {
            lowest: energy.total,
            scale: scale.max(f64::MIN_POSITIVE),
            last: energy,
            gain: None,
            released: 0.0,
        }
    }

    /// The energy after `frame`: measured, compared with the lowest before, and returned.
    pub fn observe(&mut self, simulation: &Simulation, frame: u64) -> &Energy {
        let energy = Energy::measure(simulation);
        let step = energy.total - self.last.total;
        let releasing = simulation
            .families()
            .all()
            .any(|f| self.last.violation[f].0 > VIOLATED);
        if releasing && step > 0.0 {
            // A rigid family's store, let go: the level it lifts the total to is the new floor.
            self.released += step;
            self.lowest += step;
        }
        let rise = energy.total - self.lowest;
        let largest = self.gain.as_ref().map_or(0.0, |g| g.amount);
        if rise > Self::TOLERANCE * self.scale && rise > largest {
            self.gain = Some(Gain {
                frame,
                amount: rise,
                from: grew_most(simulation, &self.last, &energy),
            });
        }
        self.lowest = self.lowest.min(energy.total);
        self.last = energy;
        &self.last
    }

    /// The bound a rise is held to, J.
    pub fn bound(&self) -> f64 {
        Self::TOLERANCE * self.scale
    }

    /// The last frame's energy.
    pub fn last(&self) -> &Energy {
        &self.last
    }
}

/// What rose most from `before` to `after`: a family's name, or the kind of energy.
fn grew_most(simulation: &Simulation, before: &Energy, after: &Energy) -> String {
    let families = simulation.families();
    let mut rises: Vec<(String, f64)> = vec![
        ("kinetic".into(), after.kinetic - before.kinetic),
        (
            "gravitational".into(),
            after.gravitational - before.gravitational,
        ),
        ("external".into(), after.external - before.external),
    ];
    rises.extend(families.all().map(|f| {
        (
            families.name(f).to_owned(),
            after.elastic[f] - before.elastic[f],
        )
    }));
    rises
        .into_iter()
        .fold((String::new(), f64::NEG_INFINITY), |a, b| {
            if b.1 > a.1 { b } else { a }
        })
        .0
}
