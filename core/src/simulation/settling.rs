//! When an edit settles ([`super::Settings::settle_edits`]): while it does, constraint
//! corrections may move particles but not speed them up. The cap is held off in one case, an
//! edit that inverted tets under a material, until they are undone and out of the basin of
//! F = 0 (`Simulation::hold_off_settling` says why), and an edit has settled when a frame's corrections fall under
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
    /// of a settling edit is held off until the next decision: while a material family is active, the edit left tets inverted (a
    /// mirror, not a flatten), a tet is still inverted or in the basin of F = 0
    /// (`basin_of_collapse`), and every active rigid family holds (within [`VIOLATED`]).
    ///
    /// Why: a mirrored material's way back under the cap does not arrive; its deviatoric term
    /// (½ μ |F|², a zero-length spring on F) shrinks the tets while the hydrostatic term, whose
    /// gradient cof F vanishes as F does, cannot push them through, and F = 0 is a local minimum
    /// of the energy (Ψ ≈ μ/2 |F|² + λ/2 γ² there, det F being cubic): the body stays squashed
    /// to a point. Only momentum carries it across: a cap eased to a few element lengths a
    /// second still left the 3 × 3 × 3 cube collapsed to a point, so the store moves the body
    /// freely (the mirrored cube at 154 m/s, 5 m across the ground), energy the account
    /// measures, not a gain. A violated rigid family is different: undoing it at full speed
    /// gives v = C / h, unbounded as h shrinks; the cap stays on while one is violated. A
    /// flattened body (det F ≥ 0 at the edit) settles under the cap throughout, even where its
    /// flat tets cross zero volume on the way back (cof F ≠ 0 there points home).
    pub(super) fn hold_off_settling(&mut self) {
        let material = self.resolved.material_family().is_some();
        if self.settling == Some(0) {
            self.edit_inverted = material && self.any_tet_below(0.0);
        }
        self.settling_held_off = self.settling.is_some()
            && material
            && self.edit_inverted
            && self.any_tet_below(self.basin_of_collapse())
            && self.largest_rigid_violation() <= VIOLATED;
    }

    /// J = V / V₀ below which a tet of the material is in the basin of F = 0 along the way
    /// back through it, F = s I: Ψ(s) = 3 μ s² / 2 + λ (s³ − γ)² / 2 has dΨ/ds = 3 μ s −
    /// 3 λ s² (γ − s³), positive (pulling the tet to F = 0 under a dissipative step) for s below
    /// the root s* of μ = λ s (γ − s³), γ = 1 + μ / λ; J* = s*³, 0.0246 at ν = 0.3 (λ here is λ_L + μ), whatever E.
    /// Found by Newton's method from s = μ / (λ γ), where s³ is negligible.
    fn basin_of_collapse(&self) -> f64 {
        basin_of_collapse(&self.settings.material)
    }
    /// Whether a tet of the body has V / V₀ below `ratio` now.
    fn any_tet_below(&self, ratio: f64) -> bool {
        let (p, rest) = (&self.state.positions, &self.body.rest_positions);
        let volume = |x: &[DVec3], t: &[u32; 4]| signed_volume(&t.map(|i| x[i as usize]));
        (self.body.tets.iter()).any(|t| volume(p, t) < ratio * volume(rest, t))
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

/// J* of `Simulation::basin_of_collapse` for `material`.
fn basin_of_collapse(material: &crate::constraints::material::Material) -> f64 {
    let (mu, lambda, gamma) = (material.mu(), material.lambda(), material.gamma());
    let mut s = mu / (lambda * gamma);
    for _ in 0..20 {
        let f = lambda * s * (gamma - s.powi(3)) - mu;
        let slope = lambda * (gamma - 4.0 * s.powi(3));
        s -= f / slope;
    }
    s.powi(3)
}

#[cfg(test)]
mod tests {
    use super::basin_of_collapse;
    use crate::constraints::material::Material;

    #[test]
    fn at_the_basins_edge_the_pull_to_f_0_and_the_push_home_balance() {
        for poisson in [0.1, 0.3, 0.45] {
            let m = Material {
                young: 1e6,
                poisson,
            };
            let j = basin_of_collapse(&m);
            let s = j.cbrt();
            let slope =
                |s: f64| 3.0 * m.mu() * s - 3.0 * m.lambda() * s * s * (m.gamma() - s.powi(3));
            assert!(slope(s).abs() < 1e-9 * m.mu(), "{poisson}: {}", slope(s));
            // Below it F = s I falls to 0, above it climbs home.
            assert!(slope(0.9 * s) > 0.0 && slope(1.1 * s) < 0.0, "{poisson}");
        }
        let j = basin_of_collapse(&Material {
            young: 1e6,
            poisson: 0.3,
        });
        assert!((j - 0.0246).abs() < 1e-4, "{j}");
    }
}
