//! When an edit settles ([`super::Settings::settle_edits`]): while it does, constraint
//! corrections may move particles but not speed them up. The cap is held off in one case, an
//! edit that inverted tets under a material, until they are undone
//! (`Simulation::hold_off_settling` says why), and an edit has settled when a frame's corrections fall under
//! [`Simulation::settle_tolerance`].

use super::Simulation;
use crate::constraints::Family;
use crate::constraints::differentiable::of_constraint;
use crate::constraints::volume::signed_volume;
use glam::DVec3;

/// A constraint counts as violated above this relative violation: |C| / |∇C|, how far its
/// particles would have to move to undo it, over its element's size (0.1 % of an element).
pub const VIOLATED: f64 = 1e-3;

impl Simulation {
    /// Whether an edit settles in the next frame: one is settling, edits settle
    /// ([`super::Resolved::edits_settle`]), and the cap is not held off.
    pub(super) fn edits_settle_now(&self) -> bool {
        self.resolved.edits_settle() && self.settling.is_some() && !self.settling_held_off
    }

    /// Decides, before a frame (and before a substep taken step by step), whether the speed cap
    /// of a settling edit is held off until the next decision: while a material family is
    /// active, the edit left tets inverted (a mirror, not a flatten), a tet still is, and every
    /// active rigid family holds (within [`VIOLATED`]).
    ///
    /// Why: a mirrored material's way back under the cap does not arrive; its deviatoric term
    /// (½ μ |F|², a zero-length spring on F) shrinks the tets while the hydrostatic term, whose
    /// gradient cof F vanishes as F does, cannot push them through, and F = 0 is a local minimum
    /// of the energy (Ψ ≈ μ/2 |F|² + λ/2 γ² there, det F being cubic): the body stays squashed
    /// to a point. Only momentum carries it across. The material's store is energy the account
    /// measures, so letting it move the body gains nothing. A violated rigid family is
    /// different: it stores no energy, and undoing it at full speed gives v = C / h, unbounded
    /// as h shrinks; the cap stays on while one is violated. A flattened body (det F ≥ 0 at the
    /// edit) settles under the cap throughout, even where its flat tets cross zero volume on
    /// the way back (cof F ≠ 0 there points home).
    pub(super) fn hold_off_settling(&mut self) {
        let material = self.resolved.material_family().is_some();
        if self.settling == Some(0) {
            self.edit_inverted = material && self.any_tet_inverted();
        }
        self.settling_held_off = self.settling.is_some()
            && material
            && self.edit_inverted
            && self.any_tet_inverted()
            && self.largest_rigid_violation() <= VIOLATED;
    }

    /// Whether a tet of the body has a negative signed volume now.
    fn any_tet_inverted(&self) -> bool {
        let p = &self.state.positions;
        let volume = |t: &[u32; 4]| signed_volume(&t.map(|i| p[i as usize]));
        self.body.tets.iter().any(|t| volume(t) < 0.0)
    }

    /// The largest relative violation ([`VIOLATED`]) among the active rigid families'
    /// constraints (α = 0) at the current positions; 0 without any.
    pub fn largest_rigid_violation(&self) -> f64 {
        let rigid = |&f: &Family| self.resolved.compliance[f] <= 0.0;
        let positions = &self.state.positions;
        (self.active().families().filter(rigid))
            .flat_map(|f| self.constraint_values(f, positions))
            .map(|(_, violation)| violation)
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max)
    }

    /// C of each of `family`'s constraints at positions `x` (one per particle), in the family's
    /// order, with its relative violation |C| / (|∇C| size): how far its particles would have to
    /// move to undo it, over its element's size (its longest rest edge), in the same units for
    /// any constraint. Not finite where ∇C vanishes and C does not.
    ///
    /// ```
    /// use tetlab_core::constraints::{Family, PerFamily};
    /// use tetlab_core::scene::{Builtin, Perturbation, Scene};
    /// use tetlab_core::simulation::{Settings, Simulation};
    /// let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
    /// let settings = Settings { active: PerFamily::builtin_list("volume").unwrap(), ..Settings::default() };
    /// let mut simulation = Simulation::new(&scene, settings);
    /// simulation.perturb(Perturbation::Flatten);
    /// let x = simulation.positions().to_vec();
    /// // A flat tet: C = −V₀, and ∇C moves its apex off the plane by a height comparable to its
    /// // size, whatever the units of C (a volume here).
    /// let (c, violation) = simulation.constraint_values(Family::VOLUME, &x).next().unwrap();
    /// assert!(c < 0.0 && violation > 0.1 && violation < 1.0, "{violation}");
    /// ```
    pub fn constraint_values<'a>(
        &'a self,
        family: Family,
        x: &'a [DVec3],
    ) -> impl Iterator<Item = (f64, f64)> + 'a {
        let body = &self.body;
        let set = &body.sets[family];
        (0..set.len()).map(move |c| {
            let rest = (set.rest()[c], set.stored(c));
            let particles = set.particles(c);
            let families = &self.families;
            let (value, gradient) =
                of_constraint(families, family, particles, rest, x, &body.rest_positions);
            let norm = gradient.iter().flatten().map(|g| g * g).sum::<f64>().sqrt();
            (value, (value / (norm * set.size()[c])).abs())
        })
    }

    /// The longest sum of Δp over the frame's substeps among particles that can move.
    pub(super) fn largest_frame_correction(&self) -> f64 {
        let s = &self.state;
        (s.frame_corrections.iter().zip(&s.inverse_masses))
            .filter(|(_, w)| **w > 0.0)
            .map(|(c, _)| c.length())
            .fold(0.0, f64::max)
    }
}
