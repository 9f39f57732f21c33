//! One contact pair described for a reader ([`Simulation::projection`] of a family that binds to
//! contacts): C and ∇C of the pair now, and the Δx and Δλ the contact pass would give it, found
//! by running that pass ([`super::project::ContactPass`]) on a copy of the pair's four
//! particles, so that what the inspector shows is what the sweep does, friction and all.

use super::project::{ContactPass, over_triangle};
use crate::constraints::Family;
use crate::simulation::{Projection, Simulation};
use glam::DVec3;

/// Where a contact pair stands, for the inspector's lines.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactState {
    /// The barycentric coordinates of p₀'s foot on the triangle (p₁, p₂, p₃) when it falls
    /// inside it; `None` when outside, where the pair is not projected.
    pub over: Option<[f64; 3]>,
    /// C where the particles were at the substep's start.
    pub at_start: f64,
    /// The floor the pair is held at: min(0, C at the substep's start).
    pub floor: f64,
}

impl Simulation {
    /// [`Projection`] of pair `c` of [`Simulation::contact_pairs`] by the contact family
    /// `family`: what the contact pass would do to it now. `delta_lambda` is `None` and
    /// `delta_x` zero where it would leave the pair alone (C at or above its floor, or p₀ not
    /// over the triangle).
    pub(crate) fn contact_projection(&self, family: Family, c: usize) -> Projection {
        let pairs = self.contact_pairs();
        let ids = pairs.get(c).copied().unwrap_or([0; 4]);
        let (state, settings) = (&self.state, &self.settings);
        let at = |array: &[DVec3]| ids.map(|i| array.get(i as usize).copied().unwrap_or_default());
        let (mut positions, mut previous) = (at(&state.positions), at(&state.previous));
        let before = positions;
        let inverse_masses = ids.map(|i| state.inverse_masses.get(i as usize).copied());
        let inverse_masses = inverse_masses.map(|w| w.unwrap_or(0.0));
        let contact = super::contact_families(&self.families, self.active());
        let slot = contact.take_while(|&f| f != family).count();
        let lambda = (state.contact_lambdas)
            .get(slot * pairs.len() + c)
            .copied()
            .unwrap_or(0.0);
        let mut lambdas = [lambda];
        let thickness = settings.contact.thickness;
        let rule = self.resolved.rule(family, self.substep_length());
        let pass = ContactPass {
            found: &[[0, 1, 2, 3]],
            order: None,
            positions: &mut positions,
            previous: &mut previous,
            inverse_masses: &inverse_masses,
            lambdas: &mut lambdas,
            thickness,
            rule,
            friction: [
                settings.contact.static_friction,
                settings.contact.kinetic_friction,
            ],
            only: (c < pairs.len()).then_some(0),
        };
        self.families.visit(family, pass);
        let constraint = self.families.constraint(family);
        let e = constraint.evaluate(&before, thickness, &before);
        let delta_x = std::array::from_fn(|k| positions[k] - before[k]);
        let moved = delta_x.iter().any(|d: &DVec3| *d != DVec3::ZERO);
        let [a, b, cc] = [before[1], before[2], before[3]];
        let size = [(a - b), (b - cc), (cc - a)].map(|e| e.length());
        Projection {
            family,
            constraint: c,
            particles: ids,
            len: 4,
            value: e.value,
            rest: thickness,
            stored: [0.0; crate::constraints::MAX_STORED],
            stored_len: 0,
            gradients: e.gradients,
            inverse_masses,
            weighted_norm: crate::simulation::projection::weighted_norm(
                &inverse_masses,
                &e.gradients,
            ),
            lambda,
            delta_lambda: (moved || lambdas[0] != lambda).then_some(lambdas[0] - lambda),
            delta_x,
            degenerate: e.degenerate,
            size: size.into_iter().fold(0.0, f64::max),
        }
    }

    /// Where contact pair `c` of [`Simulation::contact_pairs`] stands for the contact family
    /// `family` (`None` for no such pair).
    pub fn contact_state(&self, family: Family, c: usize) -> Option<ContactState> {
        let ids = *self.contact_pairs().get(c)?;
        let at = |array: &[DVec3]| ids.map(|i| array[i as usize]);
        let (now, start) = (at(&self.state.positions), at(&self.state.previous));
        let thickness = self.settings.contact.thickness;
        let constraint = self.families.constraint(family);
        let at_start = constraint.evaluate(&start, thickness, &start).value;
        Some(ContactState {
            over: over_triangle(now[0], [now[1], now[2], now[3]]),
            at_start,
            floor: if at_start < 0.0 { at_start } else { 0.0 },
        })
    }

    /// The contact pairs that `particle` belongs to (as the particle or a corner of the
    /// triangle), as indices of [`Simulation::contact_pairs`], the pairs whose particle lies
    /// over its triangle first, nearest first.
    ///
    /// ```
    /// use std::path::Path;
    /// use tetlab_core::scene::Scene;
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let text = "[[body]]\nmesh = \"cube\"\nresolution = 1\n\
    ///             [[body]]\nmesh = \"cube\"\nresolution = 1\ntranslate = [0.3, 1.005, 0]\n";
    /// let scene = Scene::parse_file(Path::new("two.toml"), text).unwrap();
    /// let mut simulation = Simulation::new(&scene, Settings::default());
    /// let families = simulation.families().clone();
    /// let active = families.parse_list("edges,volume,contact").unwrap();
    /// simulation.set_settings(Settings { active, ..Settings::default() });
    /// simulation.step();
    /// // The upper cube's bottom rests on the lower cube's top: its particles have contacts.
    /// let upper = simulation.bodies()[1].particles.clone();
    /// let (particle, pair) = upper
    ///     .filter_map(|i| simulation.contacts_of(i as usize).first().map(|&c| (i, c)))
    ///     .next()
    ///     .unwrap();
    /// assert!(simulation.contact_pairs()[pair].contains(&particle));
    /// let contact = families.parse("contact").unwrap();
    /// let projection = simulation.projection(contact, pair);
    /// // ∇ₚ₀C is the triangle's unit normal, and the four gradients sum to zero (C does not
    /// // change when the pair moves as one).
    /// let g = projection.gradients;
    /// assert!((g[0].length() - 1.0).abs() < 1e-12);
    /// assert!((g[0] + g[1] + g[2] + g[3]).length() < 1e-12);
    /// ```
    pub fn contacts_of(&self, particle: usize) -> Vec<usize> {
        let positions = &self.state.positions;
        let mut pairs: Vec<(bool, f64, usize)> = (self.contact_pairs().iter().enumerate())
            .filter(|(_, pair)| pair.contains(&(particle as u32)))
            .map(|(c, pair)| {
                let p = pair.map(|i| positions[i as usize]);
                let over = over_triangle(p[0], [p[1], p[2], p[3]]).is_some();
                let e = crate::constraints::contact::evaluate(&p, 0.0);
                (!over, e.value.abs(), c)
            })
            .collect();
        pairs.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
        pairs.into_iter().map(|(_, _, c)| c).collect()
    }
}
