//! The energy account of a state ([`Energy`]) and of a run ([`EnergyWatch`]): where a body's
//! energy is, frame by frame, and the frame where it grew.
//!
//! # Formula
//! E = K + U_g + U_f + Σ_families U_c, with
//! - K = Σᵢ ½ mᵢ |vᵢ|², the kinetic energy of the free particles (held ones have no mass here);
//! - U_g = Σᵢ mᵢ g yᵢ, gravity's, above the ground's height y = 0;
//! - U_f = −Σᵢ fᵢ·(xᵢ − x⁰ᵢ), the constant external forces', zero at the rest shape;
//! - U_c = Σ_c ½ (C_c(x)² − C_c(x⁰)²) / α_c for each active family that stores energy
//!   ([`crate::simulation::Resolved::stores_energy`]: compliant, under XPBD or a material): the
//!   energy XPBD's compliance stands for (the material's, for the neo-Hookean pair), zero at
//!   the rest shape (the pair is pre-stressed: its terms do not vanish there, their sum's
//!   gradient does); α_c is the family's, or the compliance of the own material of the body
//!   the constraint belongs to.
//!
//! Two kinds of family have a store the account cannot measure: a rigid one (α = 0), which holds
//! exactly what it holds, and one under PBD's stiffness k, which is no material constant (the
//! same k is stiffer at more substeps). A start that violates one (a mirrored body under rigid
//! edges) holds a store the account cannot see, released as motion and height while the
//! violation is undone. The account measures how far each such family is from holding
//! ([`Energy::violation`]) and books a rise of E in a frame that began with one violated as
//! that release, not as a gain, up to what the store can hold: for rigid families, whose store
//! only a violated start (an edit) fills, ½ M (L / h)² over the run, the body's mass M moving
//! its length L within one substep h, since a rigid projection undoes a violation within a
//! substep and none asks a particle to cross more than the body; for PBD's stiffness, which stores as the body strains, what
//! undoing the frame's fall in violation within a substep gives. A rise beyond that is a gain:
//! a projection along a wrong gradient (lesson 8's) pumps energy in exactly so.
//! Damping, the ground's sticking and XPBD's own dissipation take energy; nothing else gives
//! any. So beyond such a release E never grows, less rounding: [`EnergyWatch`] says where it
//! does.

use crate::constraints::{Family, PerFamily};
use crate::scene::SceneBody;
use crate::simulation::{Simulation, Taken};
use glam::DVec3;
use std::ops::Range;

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
    /// What the ground, damping and the settling cap took since the simulation was made, J
    /// (not part of the total: energy gone from the body).
    pub taken: Taken,
    /// Of each active family whose store the account cannot measure (rigid, or under PBD's
    /// stiffness), how far it is from holding: the largest and the sum of the relative violations
    /// of its constraints ([`VIOLATED`]; (0, 0) for the others, and for all where measured by
    /// [`Energy::measure`] rather than [`Energy::measure_with_violation`]). Not energy.
    #[serde(skip)]
    pub violation: PerFamily<(f64, f64)>,
}

/// A family without a measurable store counts as violated above this relative violation (0.1 %
/// of an element), and a rise of the energy while it is undone as a release of what it held.
pub use crate::simulation::VIOLATED;

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
        let whole = 0..simulation.positions().len() as u32;
        let positions = simulation.positions();
        let squares = |family: Family| {
            let set = &simulation.body().sets[family];
            let mut now = Squares::default();
            for (c, (value, _)) in simulation.constraint_values(family, positions).enumerate() {
                now.add(value, set.own_compliance(c));
            }
            let (plain, own) = set.rest_squared();
            (now, Squares { plain, own })
        };
        Energy {
            taken: simulation.state().taken,
            ..Energy::measure_part(simulation, &whole, squares)
        }
    }

    /// The energy of each body of a scene of several ([`Simulation::bodies`]) on its own: its
    /// name and its [`Energy`], of its particles and of the constraints whose first particle is
    /// its (a body's elements have none outside it). The bodies' totals add up to the scene's
    /// ([`Energy::measure`]); what left the scene ([`Energy::taken`]) is not told apart by body
    /// and is zero here. Empty for a scene of one body. Each family's constraints are evaluated
    /// once, now and at rest, whatever the number of bodies.
    ///
    /// ```
    /// use tetlab_core::measures::energy_account::Energy;
    /// use tetlab_core::scene::Scene;
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let text = "[[body]]\nmesh = \"cube\"\nresolution = 1\n\
    ///             [[body]]\nmesh = \"tet\"\ntranslate = [0, 2, 0]\nvelocity = [0, 0, 3]\n";
    /// let scene = Scene::parse_file("two.toml".as_ref(), text).unwrap();
    /// let mut simulation = Simulation::new(&scene, Settings::default());
    /// simulation.step();
    /// let bodies = Energy::measure_bodies(&simulation);
    /// let sum: f64 = bodies.iter().map(|(_, e)| e.total).sum();
    /// let whole = Energy::measure(&simulation).total;
    /// assert!((sum - whole).abs() <= 1e-12 * whole.abs());
    /// // Only the tet was launched: the cube, at rest on the ground, moves far slower.
    /// assert!(bodies[1].1.kinetic > 100.0 * bodies[0].1.kinetic);
    /// ```
    pub fn measure_bodies(simulation: &Simulation) -> Vec<(String, Energy)> {
        let bodies = simulation.bodies();
        // Σ C² per body, now and at rest, of each family that stores energy.
        let mut squares = PerFamily::<Vec<(Squares, Squares)>>::default();
        let resolved = simulation.resolved();
        for family in simulation.families().all() {
            if !simulation.active()[family] || !resolved.stores_energy(family) {
                continue;
            }
            let sums = &mut squares[family];
            sums.resize(bodies.len(), Default::default());
            let set = simulation.constraints(family);
            let now = simulation.constraint_values(family, simulation.positions());
            let rest = simulation.constraint_values(family, simulation.rest_positions());
            for (c, ((now, _), (rest, _))) in now.zip(rest).enumerate() {
                let body = SceneBody::owner(bodies, set.particles(c)[0]);
                if let Some(sum) = body.and_then(|b| sums.get_mut(b)) {
                    let own = set.own_compliance(c);
                    sum.0.add(now, own);
                    sum.1.add(rest, own);
                }
            }
        }
        (bodies.iter().enumerate())
            .map(|(b, body)| {
                let of = |family: Family| squares[family].get(b).copied().unwrap_or_default();
                let energy = Energy::measure_part(simulation, &body.particles, of);
                (body.name.clone(), energy)
            })
            .collect()
    }

    /// The energy of the particles `part` of `simulation` and of the constraints whose first
    /// particle is among them, with `squares(family)` their squared values now and at rest,
    /// asked only of an active family that stores energy ([`Energy::taken`] left zero).
    fn measure_part(
        simulation: &Simulation,
        part: &Range<u32>,
        squares: impl Fn(Family) -> (Squares, Squares),
    ) -> Energy {
        let body = simulation.body();
        let gravity = simulation.settings().gravity;
        let (mut kinetic, mut gravitational, mut external) = (0.0, 0.0, 0.0);
        let positions = simulation.positions();
        let range = part.start as usize..part.end as usize;
        let inverse_masses = &simulation.inverse_masses()[range.clone()];
        for ((i, &w), v) in range
            .clone()
            .zip(inverse_masses)
            .zip(&simulation.velocities()[range])
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
        let resolved = simulation.resolved();
        let elastic = simulation.families().per_family(|family| {
            if !simulation.active()[family] || !resolved.stores_energy(family) {
                return 0.0;
            }
            let (now, rest) = squares(family);
            let alpha = resolved.compliance[family];
            0.5 * ((now.plain - rest.plain) / alpha + (now.own - rest.own))
        });
        let elastic_sum: f64 = simulation.families().all().map(|f| elastic[f]).sum();
        Energy {
            kinetic,
            gravitational,
            external,
            total: kinetic + gravitational + external + elastic_sum,
            taken: Taken::default(),
            elastic,
            violation: PerFamily::default(),
        }
    }

    /// The elastic energy of every family of `families`, J.
    pub fn elastic_total(&self, families: &crate::constraints::Families) -> f64 {
        families.all().map(|f| self.elastic[f]).sum()
    }

    /// What a plot of the account shows, named: `kinetic`, `gravitational`, `external`,
    /// `elastic` (every family's, [`Energy::elastic_total`]) and `total`, J.
    pub fn parts(&self, families: &crate::constraints::Families) -> [(&'static str, f64); 5] {
        [
            ("kinetic", self.kinetic),
            ("gravitational", self.gravitational),
            ("external", self.external),
            ("elastic", self.elastic_total(families)),
            ("total", self.total),
        ]
    }

    /// [`Energy::measure`] with [`Energy::violation`] too: how far each family without a
    /// measurable store is from holding, which a run's account ([`EnergyWatch`]) needs and a
    /// display does not (it costs a C and a ∇C per constraint of those families every frame).
    pub fn measure_with_violation(simulation: &Simulation) -> Energy {
        let mut energy = Energy::measure(simulation);
        let resolved = simulation.resolved();
        let positions = simulation.positions();
        energy.violation = simulation.families().per_family(|family| {
            if !simulation.active()[family] || resolved.stores_energy(family) {
                return (0.0, 0.0);
            }
            violation(simulation, family, positions)
        });
        energy
    }
}

/// A family's squared values: Σ C² over the constraints that take the family's compliance α,
/// and Σ C² / α_c over those with one of their own (a body's material,
/// [`crate::simulation::ConstraintSet::own_compliance`]); a C that is not finite left out.
#[derive(Clone, Copy, Debug, Default)]
struct Squares {
    plain: f64,
    own: f64,
}

impl Squares {
    /// Adds C of a constraint whose own compliance is `own`.
    fn add(&mut self, value: f64, own: Option<f64>) {
        if value.is_finite() {
            match own {
                Some(alpha) => self.own += value * value / alpha,
                None => self.plain += value * value,
            }
        }
    }
}

/// max_c and Σ_c of the relative violation of `family`'s constraints at positions `x`
/// ([`crate::simulation::VIOLATED`]), those with a finite one.
fn violation(simulation: &Simulation, family: Family, x: &[DVec3]) -> (f64, f64) {
    (simulation.constraint_values(family, x))
        .map(|(_, violation)| violation)
        .filter(|v| v.is_finite())
        .fold((0.0, 0.0), |(largest, sum), v| (largest.max(v), sum + v))
}

/// Where a run's energy grew past the bound: the frame, by how much (J), and what grew most in
/// that frame (a family's name, or "kinetic", "gravitational", "external").
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Gain {
    /// The frame at whose end the total was highest above its lowest before.
    pub frame: u64,
    /// The total at that frame less the lowest total before it, J, what left the body between
    /// them added back ([`EnergyWatch`]).
    pub amount: f64,
    /// What rose most over that frame.
    pub from: String,
}

/// A run's energy, frame by frame: the lowest total so far, and the largest rise above it, with
/// what left the body added back to the total: what the ground and damping took since the start
/// ([`Taken`]). So energy the ground takes in a landing cannot hide a gain elsewhere in the same
/// frame.
///
/// A run that only loses energy never rises above its lowest total. The bound a rise is held to
/// is [`EnergyWatch::TOLERANCE`] of the run's scale: the start's kinetic, elastic and external
/// energy plus its weight times its height above the ground and the body's size (what it could
/// give back at most), plus what rounding can make of a body that holds nothing (its mass moving
/// a body length a frame at f32's precision), so that rounding in the sums is never a gain.
#[derive(Clone, Debug)]
pub struct EnergyWatch {
    lowest: f64,
    /// What the rigid families' violated start can still release, J: at most the body's mass
    /// moving its length within one substep, ½ M (L / h)², since a rigid projection undoes a
    /// violation within a substep and none asks a particle to cross more than the body.
    budget: f64,
    /// The mass of the free particles, kg.
    mass: f64,
    scale: f64,
    /// The total at the start, J.
    pub start_total: f64,
    /// What had left the body at the start ([`Energy::taken`]), J.
    start_taken: Taken,
    /// Whether some active family has a store the account cannot measure (rigid, or under PBD's
    /// stiffness): then what the solver's projections dissipated cannot be told.
    unmeasured: bool,
    last: Energy,
    /// The largest rise above the lowest total before it, once it passed the bound.
    pub gain: Option<Gain>,
    /// What families without a measurable store (rigid, or under PBD's stiffness) released so
    /// far (J): the rises of frames that began with one violated (beyond [`VIOLATED`]), up to
    /// what its store can hold (module docs).
    pub released: f64,
}

impl EnergyWatch {
    /// The fraction of the run's scale a rise may reach before it counts: 1 %.
    pub const TOLERANCE: f64 = 0.01;

    /// A watch from `simulation`'s state now (frame 0).
    pub fn start(simulation: &Simulation) -> EnergyWatch {
        let energy = Energy::measure_with_violation(simulation);
        let body = simulation.body();
        let size = body.rest_diagonal();
        let mass: f64 = (simulation.inverse_masses().iter())
            .zip(&body.lumped_inverse_masses)
            .filter(|(w, _)| **w > 0.0)
            .map(|(_, lumped)| 1.0 / lumped)
            .sum();
        let weight = mass * simulation.settings().gravity.abs();
        // What rounding alone can make of a body that holds nothing (no gravity, at rest): its
        // mass moving a body length a frame, at f32's relative precision (the fast engine's).
        let rounding = mass * (size / simulation.settings().dt).powi(2) * f64::from(f32::EPSILON);
        let elastic: f64 = simulation.families().all().map(|f| energy.elastic[f]).sum();
        let scale = energy.kinetic
            + elastic.abs()
            + energy.external.abs()
            + energy.gravitational.abs()
            + weight * size
            + rounding;
        EnergyWatch {
            lowest: energy.total,
            budget: {
                let rigid = |f: &Family| simulation.resolved().compliance[*f] <= 0.0;
                let violated = (simulation.families().all().filter(rigid))
                    .any(|f| energy.violation[f].0 > VIOLATED);
                let v = size / simulation.substep_length();
                if violated { 0.5 * mass * v * v } else { 0.0 }
            },
            mass,
            start_total: energy.total,
            start_taken: energy.taken,
            unmeasured: (simulation.families().all())
                .any(|f| simulation.active()[f] && !simulation.resolved().stores_energy(f)),
            scale: scale.max(f64::MIN_POSITIVE),
            last: energy,
            gain: None,
            released: 0.0,
        }
    }

    /// The energy after `frame`: measured, compared with the lowest before, and returned.
    pub fn observe(&mut self, simulation: &Simulation, frame: u64) -> &Energy {
        let energy = Energy::measure_with_violation(simulation);
        let step = self.held(&energy) - self.held(&self.last);
        // A store the account cannot measure is released while it is undone (module docs):
        // a rigid family's from the budget its violated start holds, in frames that begin with
        // it violated; one under PBD's stiffness as its strain goes, up to what undoing that
        // much within a substep can give.
        let speed = |d: f64| d * simulation.body().mean_edge / simulation.substep_length();
        let (mut rigid, mut stiffness) = (false, 0.0f64);
        for f in simulation.families().all() {
            let (before, after) = (self.last.violation[f], energy.violation[f]);
            if before.0 <= VIOLATED {
                continue;
            }
            if simulation.resolved().compliance[f] <= 0.0 {
                rigid = true;
            } else {
                let v = speed((before.1 - after.1).max(0.0));
                stiffness = stiffness.max(0.5 * self.mass * v * v);
            }
        }
        let available = stiffness + if rigid { self.budget } else { 0.0 };
        if step > 0.0 && available > 0.0 {
            let release = step.min(available);
            self.budget -= (release - stiffness).clamp(0.0, self.budget);
            // An unmeasured store, let go: the level it lifts the total to is the new floor.
            self.released += release;
            self.lowest += release;
        }
        let rise = self.held(&energy) - self.lowest;
        let largest = self.gain.as_ref().map_or(0.0, |g| g.amount);
        if rise > Self::TOLERANCE * self.scale && rise > largest {
            self.gain = Some(Gain {
                frame,
                amount: rise,
                from: grew_most(simulation, &self.last, &energy),
            });
        }
        self.lowest = self.lowest.min(self.held(&energy));
        self.last = energy;
        &self.last
    }

    /// The total of `energy` with what the ground and damping took since the start added back,
    /// J: what the watch holds to never rise. What the settling cap took is not: the cap removes
    /// only speed a frame's projections gave beyond what a particle had, which never was in the
    /// account (a rigid family's store let go, or a gain cut off as it was made), so adding it
    /// back would count that release a second time.
    fn held(&self, energy: &Energy) -> f64 {
        let taken = energy.taken - self.start_taken;
        energy.total + taken.ground + taken.damping
    }

    /// What the ground, damping and the settling cap took since the start, J.
    pub fn taken(&self) -> Taken {
        self.last.taken - self.start_taken
    }

    /// The bound a rise is held to, J.
    pub fn bound(&self) -> f64 {
        Self::TOLERANCE * self.scale
    }

    /// The last frame's energy.
    pub fn last(&self) -> &Energy {
        &self.last
    }

    /// What a front end prints of the account: the total at the start and now with the parts
    /// of the last, what left the body (where more than a thousandth of the bound) and, where
    /// every active family's store is measured, what the solver's projections dissipated beside
    /// it, what unmeasured stores released (if any),
    /// and a warning naming the frame and what rose most where the total grew past the bound.
    ///
    /// ```
    /// use tetlab_core::measures::energy_account::EnergyWatch;
    /// use tetlab_core::scene::{Builtin, Scene};
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    /// let mut simulation = Simulation::new(&scene, Settings::default());
    /// let mut watch = EnergyWatch::start(&simulation);
    /// simulation.step();
    /// watch.observe(&simulation, 1);
    /// // A cube at rest on the ground keeps its energy: one line, no warning.
    /// let lines = watch.lines();
    /// assert_eq!(lines.len(), 1);
    /// assert!(lines[0].starts_with("energy: "), "{lines:?}");
    /// ```
    pub fn lines(&self) -> Vec<String> {
        let last = &self.last;
        let elastic = last.total - last.kinetic - last.gravitational - last.external;
        let mut lines = vec![format!(
            "energy: {:.4e} J at the start, {:.4e} J at the end (kinetic {:.3e}, gravitational \
             {:.3e}, elastic {:.3e})",
            self.start_total, last.total, last.kinetic, last.gravitational, elastic
        )];
        let taken = self.taken();
        if taken.total() > 1e-3 * self.bound() {
            let mut line = format!(
                "energy that left the body: {:.4e} J to the ground, {:.4e} J to damping, {:.4e} \
                 J to the settling cap",
                taken.ground, taken.damping, taken.settling
            );
            // With every store measured, the rest of what the total lost is the solver's own.
            if !self.unmeasured {
                let solver = self.start_total - last.total - taken.total();
                line += &format!("; the solver's projections dissipated {solver:.4e} J");
            }
            lines.push(line);
        }
        if self.released > 0.0 {
            lines.push(format!(
                "energy released by families undoing their violation: {:.4e} J (a rigid family, or \
                 one under PBD's stiffness, stores no energy the account can measure)",
                self.released
            ));
        }
        if let Some(gain) = &self.gain {
            lines.push(format!(
                "warning: the energy grew by {:.3e} J above its lowest by frame {} (more than \
                 {:.3e} J, 1 % of what the body could give back), most in {}",
                gain.amount,
                gain.frame,
                self.bound(),
                gain.from
            ));
        }
        lines
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
