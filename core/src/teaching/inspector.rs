//! What the inspector shows about a constraint: its numbers as the solver sees them
//! ([`Projection`]) and its analytic gradient checked against central differences, live; for a
//! constraint file's family, ∇C by automatic differentiation beside the file's own.

use crate::constraints::Family;
use crate::constraints::verify::{analytic_and_numeric, relative_error};
use crate::simulation::{Projection, Simulation};
use glam::DVec3;

/// One constraint, inspected.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inspection {
    /// C, ∇C, w, λ, Δλ and Δx, as the next projection would compute them.
    pub projection: Projection,
    /// ∇ₚC by central differences, per particle (the first `projection.len`).
    pub numeric_gradients: [DVec3; 4],
    /// maxᵢ |∇ₚᵢC − ∇ₚᵢC_fd|∞ / maxᵢ |∇ₚᵢC| (see [`relative_error`]).
    pub relative_error: f64,
    /// For a family read from a constraint file: ∇C by AD and the file's own, side by side.
    pub file_gradients: Option<FileGradients>,
}

/// The two gradients of a constraint file's constraint, per particle (the first
/// `projection.len`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FileGradients {
    /// ∇ₚC by automatic differentiation (zero where it is undefined).
    pub automatic: [DVec3; 4],
    /// The file's own ∇ₚC, for each particle it gives one for.
    pub yours: [Option<DVec3>; 4],
}

impl Inspection {
    /// Σᵢ |∇ₚᵢC|², unweighted.
    pub fn gradient_norm_squared(&self) -> f64 {
        let p = &self.projection;
        p.gradients[..p.len]
            .iter()
            .map(|g| g.length_squared())
            .sum()
    }
}

/// Inspects constraint `c` of `family` in the current state of `simulation`.
///
/// ```
/// use tetlab_core::constraints::Family;
/// use tetlab_core::teaching::inspector::inspect;
/// use tetlab_core::scene::{Builtin, Perturbation, Scene};
/// use tetlab_core::simulation::{Settings, Simulation};
/// let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
/// let mut simulation = Simulation::new(&scene, Settings::default());
/// simulation.perturb(Perturbation::Invert);
/// let volume = inspect(&simulation, Family::VOLUME, 0);
/// // Inverted: C = −2V, and the analytic gradient agrees with central differences.
/// assert!((volume.projection.value + 2.0 * volume.projection.rest).abs() < 1e-12);
/// assert!(volume.relative_error < 1e-6);
/// ```
pub fn inspect(simulation: &Simulation, family: Family, c: usize) -> Inspection {
    let projection = simulation.projection(family, c);
    let (points, rest_shape) = particles_of(simulation, &projection);
    let families = simulation.families();
    let (analytic, numeric) =
        analytic_and_numeric(families, family, &points, projection.rest, &rest_shape);
    let mut numeric_gradients = [DVec3::ZERO; 4];
    numeric_gradients[..numeric.len()].copy_from_slice(&numeric);
    let file_gradients = families.file(family).map(|file| {
        let automatic = file.gradients_of(&points, projection.rest, projection.stored(), false);
        FileGradients {
            automatic,
            yours: file.yours(&points, projection.rest, projection.stored()),
        }
    });
    Inspection {
        projection,
        numeric_gradients,
        relative_error: relative_error(&analytic, &numeric),
        file_gradients,
    }
}

/// What else the family shows of the inspected constraint ([`crate::constraints::AnyConstraint::describe_state`]: F and
/// det F for the neo-Hookean pair), one line each.
/// Of a contact pair: whether p₀ lies over the triangle, C at the substep's start and the floor
/// the pair is held at, which say whether and how the contact pass projects it.
pub fn state_lines(simulation: &Simulation, projection: &Projection) -> Vec<String> {
    let (family, c) = (projection.family, projection.constraint);
    if let Some(contact) = simulation
        .contact_state(family, c)
        .filter(|_| simulation.families().binding(family) == crate::constraints::Binding::Contacts)
    {
        let over = match contact.over {
            Some([a, b, c]) => {
                format!("p₀ is over the triangle: its foot at b = ({a:.3}, {b:.3}, {c:.3})")
            }
            None => "p₀ is not over the triangle: the pair is left alone".to_owned(),
        };
        let floor = format!(
            "C at the substep's start = {:+.4e}; held at C ≥ {:+.4e} (projected only below it)",
            contact.at_start, contact.floor
        );
        return vec![over, floor];
    }
    let (points, rest_shape) = particles_of(simulation, projection);
    (simulation.families().constraint(family)).describe_state(&points, &rest_shape)
}

/// The constraint's particles now and at rest.
fn particles_of(simulation: &Simulation, projection: &Projection) -> (Vec<DVec3>, Vec<DVec3>) {
    let at = |positions: &[DVec3]| -> Vec<DVec3> {
        projection
            .particles()
            .iter()
            .map(|&i| positions[i as usize])
            .collect()
    };
    (at(simulation.positions()), at(simulation.rest_positions()))
}

/// Inspects every constraint of the active families on tet `tet`, family by family. Appends to
/// `out`.
pub fn inspect_tet(simulation: &Simulation, tet: usize, out: &mut Vec<Inspection>) {
    let active = *simulation.active();
    for family in active.families() {
        for c in simulation.tet_constraints(tet, family) {
            out.push(inspect(simulation, family, c));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constraints::PerFamily;
    use crate::scene::{Builtin, Perturbation, Scene};
    use crate::simulation::Settings;

    /// A contact pair inspected: its gradient agrees with central differences, and its lines
    /// say whether the particle is over its triangle.
    #[test]
    fn a_contact_pair_is_inspected_like_a_constraint() {
        let at = [0.3, 1.003, 0.2];
        let simulation = crate::simulation::contact::cube_on_cube(2, at, Settings::default(), 5);
        let contact = simulation.families().parse("contact").unwrap();
        let pairs = simulation.contact_pairs().len();
        assert!(pairs > 0);
        let mut over = 0;
        for c in 0..pairs {
            let inspection = inspect(&simulation, contact, c);
            let p = &inspection.projection;
            assert_eq!(p.particles, simulation.contact_pairs()[c]);
            assert!(inspection.relative_error < 1e-6, "{inspection:?}");
            assert_eq!(p.rest, simulation.settings().contact.thickness);
            let lines = state_lines(&simulation, p);
            assert_eq!(lines.len(), 2, "{lines:?}");
            over += usize::from(lines[0].starts_with("p₀ is over"));
        }
        assert!(over > 0, "no pair of {pairs} lies over its triangle");
    }

    #[test]
    fn a_tet_shows_six_edges_four_heights_and_one_volume_all_checked() {
        let scene = Scene::builtin(Builtin::Cube, 1).unwrap();
        let settings = Settings {
            active: PerFamily::splat(true),
            ..Settings::default()
        };
        let mut simulation = Simulation::new(&scene, settings);
        simulation.perturb(Perturbation::Scramble(2));
        let mut out = Vec::new();
        inspect_tet(&simulation, 3, &mut out);
        let count = |f: Family| out.iter().filter(|i| i.projection.family == f).count();
        assert_eq!(
            [Family::EDGES, Family::HEIGHT, Family::VOLUME].map(count),
            [6, 4, 1]
        );
        for inspection in &out {
            let p = &inspection.projection;
            assert!(
                p.particles()
                    .iter()
                    .all(|i| simulation.tets()[3].contains(i))
            );
            assert!(inspection.relative_error < 1e-5, "{p:?}");
            let sum: f64 = (0..p.len)
                .map(|k| p.inverse_masses[k] * p.gradients[k].length_squared())
                .sum();
            assert!((sum - p.weighted_norm).abs() <= 1e-12 * sum);
            assert!(inspection.gradient_norm_squared() > 0.0);
        }
    }
}
