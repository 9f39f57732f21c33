//! The simulation that every front end drives: XPBD (default) or PBD on the three constraint
//! families, with substeps, gravity, a ground plane, pins and a grab constraint.
//!
//! One substep of length h = Δt / substeps:
//! 1. predict: v += g h, x_prev = x, x += v h; a particle predicted below the ground (y < 0) is put
//!    back at its previous position, on the ground (sticking friction);
//! 2. XPBD only: λ = 0 for every constraint;
//! 3. `iterations` Gauss–Seidel sweeps over the active families in a fixed order (edges, plane,
//!    volume, then the grab, then the ground y ≥ 0), each constraint projected at once;
//! 4. v = (x − x_prev) / h, then damped: v *= max(0, 1 − damping · h) — except, with
//!    [`Settings::settle_edits`], while an edit settles: there |v| is also capped at the predicted
//!    speed, so the projections may turn the motion but never speed it up.
//!
//! The correction Δp of a substep is, per particle, the position after the sweeps minus the
//! predicted one ([`Simulation::corrections`]). An edit (a perturbation, a particle placed by hand)
//! settles until the largest Δp of a substep is below [`Simulation::settle_tolerance`], or for at
//! most [`MAX_SETTLE_FRAMES`] frames.
//!
//! Projecting one constraint C with particles i, gradients ∇ᵢC and inverse masses wᵢ:
//! - XPBD: α̃ = α / h², Δλ = (−C − α̃ λ) / (Σ wᵢ|∇ᵢC|² + α̃), λ += Δλ, Δxᵢ = wᵢ ∇ᵢC Δλ;
//! - PBD: s = −C / Σ wᵢ|∇ᵢC|², Δxᵢ = k′ s wᵢ ∇ᵢC with k′ = 1 − (1 − k)^(1/iterations), so that
//!   `iterations` sweeps of stiffness k′ compound to k.
//!
//! Degenerate evaluations (undefined ∇C), constraints whose particles are all pinned, and
//! constraints whose free particles can barely change them ([`LOCKED`]) are skipped. All state lives in flat arrays, one set per family, allocated once: a step allocates
//! nothing, and the same inputs give the same bits.

use crate::constraints::{Evaluation, Family, distance, plane, volume};
use crate::divergence::Divergence;
use crate::integrate;
use crate::limits;
use crate::mesh::{TET_EDGES, TetMesh};
use crate::scene::Scene;
use crate::vector::{Real, Vector3};
use glam::DVec3;

/// XPBD or PBD.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Method {
    /// Extended PBD: compliance per family, λ accumulated within a substep.
    Xpbd,
    /// Müller et al. 2006: stiffness per family, corrected for the iteration count.
    Pbd,
}

impl Method {
    /// `xpbd` or `pbd`.
    pub fn parse(text: &str) -> Result<Method, String> {
        match text.trim() {
            "xpbd" => Ok(Method::Xpbd),
            "pbd" => Ok(Method::Pbd),
            other => Err(format!("'{other}' is not a solver: expected xpbd or pbd")),
        }
    }

    /// The name [`Method::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Method::Xpbd => "xpbd",
            Method::Pbd => "pbd",
        }
    }
}

/// One value per constraint family.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PerFamily<T> {
    /// Edge distance.
    pub edges: T,
    /// The four heights per tet.
    pub plane: T,
    /// Signed volume.
    pub volume: T,
}

impl PerFamily<bool> {
    /// The families named in a comma-separated list (`edges,volume`), each as [`Family::parse`]
    /// reads it.
    pub fn parse_list(text: &str) -> Result<PerFamily<bool>, String> {
        let mut active = PerFamily::splat(false);
        for name in text.split(',') {
            active.set(Family::parse(name)?, true);
        }
        Ok(active)
    }

    /// The active families as `edges+plane+volume`, or `none`.
    pub fn describe(&self) -> String {
        let names: Vec<&str> = Family::ALL
            .into_iter()
            .filter(|&f| self.get(f))
            .map(Family::short_name)
            .collect();
        if names.is_empty() {
            "none".into()
        } else {
            names.join("+")
        }
    }
}

impl<T: Copy> PerFamily<T> {
    /// The same value for every family.
    pub const fn splat(value: T) -> Self {
        Self {
            edges: value,
            plane: value,
            volume: value,
        }
    }

    /// The value for `family`.
    pub fn get(&self, family: Family) -> T {
        match family {
            Family::Distance => self.edges,
            Family::Plane => self.plane,
            Family::Volume => self.volume,
        }
    }

    /// Sets the value for `family`.
    pub fn set(&mut self, family: Family, value: T) {
        match family {
            Family::Distance => self.edges = value,
            Family::Plane => self.plane = value,
            Family::Volume => self.volume = value,
        }
    }
}

/// How the simulation runs. Every field may change between steps.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Settings {
    /// XPBD or PBD.
    pub method: Method,
    /// Which families are projected.
    pub active: PerFamily<bool>,
    /// XPBD compliance α per family: the inverse of stiffness, 0 is rigid, larger is softer.
    pub compliance: PerFamily<f64>,
    /// PBD stiffness k ∈ [0, 1] per family.
    pub stiffness: PerFamily<f64>,
    /// Substeps per frame, ≥ 1.
    pub substeps: u32,
    /// Gauss–Seidel sweeps per substep, ≥ 1.
    pub iterations: u32,
    /// Frame length Δt in seconds.
    pub dt: f64,
    /// Gravity along −y in m/s².
    pub gravity: f64,
    /// Whether the ground plane y = 0 stops particles.
    pub ground: bool,
    /// Velocity damping per second.
    pub damping: f64,
    /// Compliance of the grab constraint; 0 moves the grabbed particle with the target exactly.
    pub grab_compliance: f64,
    /// After an edit (a perturbation or a particle placed by hand), constraint corrections may
    /// move particles but not speed them up, until the edit's violation is undone. Otherwise rigid
    /// constraints undo a large violation within a substep, and v = Δx/h launches the body.
    pub settle_edits: bool,
}

impl Settings {
    /// Sets gravity, and the ground with it: on when g ≠ 0, off in weightlessness (the rule of
    /// the command line and of lessons; the workbench also lets the user set the ground apart).
    pub fn set_gravity(&mut self, gravity: f64) {
        self.gravity = gravity;
        self.ground = gravity != 0.0;
    }

    /// Ok when every number is within its range of [`crate::limits`]; otherwise the first that
    /// is not, named (e.g. settings remembered by an older workbench, or edited by hand).
    pub fn check(&self) -> Result<(), String> {
        limits::SUBSTEPS.check(self.substeps)?;
        limits::ITERATIONS.check(self.iterations)?;
        limits::DT.check(self.dt)?;
        limits::GRAVITY.check(self.gravity)?;
        limits::DAMPING.check(self.damping)?;
        limits::COMPLIANCE
            .check(self.grab_compliance)
            .map_err(|e| format!("grab {e}"))?;
        for family in Family::ALL {
            let name = family.short_name();
            limits::COMPLIANCE
                .check(self.compliance.get(family))
                .map_err(|e| format!("{e} ({name})"))?;
            limits::STIFFNESS
                .check(self.stiffness.get(family))
                .map_err(|e| format!("{e} ({name})"))?;
        }
        Ok(())
    }

    /// Constraint projections in one frame, given how many constraints each family has: the
    /// active families' counts × substeps × iterations.
    pub fn projections_per_frame(&self, counts: PerFamily<usize>) -> u64 {
        let per_sweep: usize = Family::ALL
            .into_iter()
            .filter(|&f| self.active.get(f))
            .map(|f| counts.get(f))
            .sum();
        per_sweep as u64 * self.substeps.max(1) as u64 * self.iterations.max(1) as u64
    }
}

impl Default for Settings {
    /// XPBD, edges + volume, rigid, 10 substeps of 1 iteration, Δt = 1/60 s, gravity 9.81 m/s²,
    /// ground on, no damping.
    fn default() -> Self {
        Self {
            method: Method::Xpbd,
            active: PerFamily {
                edges: true,
                plane: false,
                volume: true,
            },
            compliance: PerFamily::splat(0.0),
            stiffness: PerFamily::splat(1.0),
            substeps: 10,
            iterations: 1,
            dt: 1.0 / 60.0,
            gravity: 9.81,
            ground: true,
            damping: 0.0,
            grab_compliance: 0.0,
            settle_edits: false,
        }
    }
}

/// The largest coordinate or velocity component (in m or m/s) a sound simulation in f64 has:
/// below it, volumes (cubes), squared residuals and their sums over any mesh stay finite.
pub const SOUND_LIMIT: f64 = 1e30;

/// Density used to lump masses: 1000 kg/m³.
pub const DENSITY: f64 = 1000.0;

/// The longest an edit settles, in frames (one second at 60 frames per second).
pub const MAX_SETTLE_FRAMES: u32 = 60;

/// An edit has settled when no particle is corrected by more than this fraction of the mean rest
/// edge length in a substep (plus what gravity alone causes; see [`Simulation::settle_tolerance`]).
pub const SETTLE_FRACTION: f64 = 1e-3;

/// The constraints of one family: particle indices, rest values and XPBD multipliers, one entry
/// per constraint, in projection order.
#[derive(Clone, Debug, Default)]
pub struct ConstraintSet<const N: usize> {
    /// The particles of each constraint, in the constraint's own order.
    pub particles: Vec<[u32; N]>,
    /// The rest value (d or V) of each constraint.
    pub rest: Vec<f64>,
    /// The XPBD multiplier λ of each constraint, accumulated within the current substep.
    pub lambda: Vec<f64>,
}

impl<const N: usize> ConstraintSet<N> {
    fn new(
        particles: Vec<[u32; N]>,
        positions: &[DVec3],
        evaluate: fn(&[DVec3; N], f64) -> Evaluation<DVec3, N>,
    ) -> Self {
        let rest = particles
            .iter()
            .map(|idx| evaluate(&idx.map(|i| positions[i as usize]), 0.0).value)
            .collect();
        let lambda = vec![0.0; particles.len()];
        Self {
            particles,
            rest,
            lambda,
        }
    }

    /// The number of constraints.
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }
}

/// The change one projection makes: Δλ (XPBD; the scaled step s for PBD) and Δx per particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Correction<const N: usize, V: Vector3 = DVec3> {
    /// XPBD: Δλ. PBD: k′ s.
    pub delta_lambda: V::Real,
    /// Δx for each particle of the constraint.
    pub delta_x: [V; N],
}

/// How a correction is scaled: XPBD with α̃ = α / h², or PBD with the per-iteration stiffness k′.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Rule<R> {
    Xpbd { alpha_tilde: R },
    Pbd { k: R },
}

impl Rule<f64> {
    /// The rule `settings` give `family` in a substep of length h: XPBD α̃ = α / h², or PBD
    /// k′ = 1 − (1 − k)^(1/iterations), so that the sweeps of a substep compound to k.
    pub(crate) fn for_settings(settings: &Settings, family: Family, h: f64) -> Rule<f64> {
        match settings.method {
            Method::Xpbd => Rule::Xpbd {
                alpha_tilde: settings.compliance.get(family) / (h * h),
            },
            Method::Pbd => {
                let k = settings.stiffness.get(family).clamp(0.0, 1.0);
                let n = settings.iterations.max(1) as f64;
                Rule::Pbd {
                    k: 1.0 - (1.0 - k).powf(1.0 / n),
                }
            }
        }
    }

    /// The same rule in another precision.
    pub(crate) fn to<R: Real>(self) -> Rule<R> {
        match self {
            Rule::Xpbd { alpha_tilde } => Rule::Xpbd {
                alpha_tilde: R::from_f64(alpha_tilde),
            },
            Rule::Pbd { k } => Rule::Pbd { k: R::from_f64(k) },
        }
    }
}

/// The correction that projecting one constraint would make, or `None` when it is skipped
/// (degenerate, or every particle pinned). In any precision: the f64 path and the fast f32 path
/// share it, through [`correction_lanes`].
#[inline]
pub(crate) fn correction<V: Vector3, const N: usize>(
    evaluation: Evaluation<V, N>,
    weights: [V::Real; N],
    lambda: V::Real,
    rule: Rule<V::Real>,
) -> Option<Correction<N, V>>
where
    V::Real: Real<Mask = bool>,
{
    let (skipped, correction) = correction_lanes(evaluation, weights, lambda, rule);
    (!skipped).then_some(correction)
}

/// The projection rule without a branch, for one constraint or several in lanes:
/// Σ wᵢ|∇ᵢC|²; XPBD Δλ = (−C − α̃λ) / (Σ wᵢ|∇ᵢC|² + α̃), PBD Δλ = −k′C / Σ wᵢ|∇ᵢC|²; Δxᵢ = wᵢ ∇ᵢC Δλ.
/// The mask is set and the correction is zero where the evaluation is degenerate, where
/// Σ wᵢ|∇ᵢC|² is not positive and finite (every particle fixed), and where the constraint is
/// [`LOCKED`]: its free particles can barely change it.
#[inline(always)]
pub(crate) fn correction_lanes<V: Vector3, const N: usize>(
    evaluation: Evaluation<V, N>,
    weights: [V::Real; N],
    lambda: V::Real,
    rule: Rule<V::Real>,
) -> (<V::Real as Real>::Mask, Correction<N, V>) {
    // Σ wᵢ|∇ᵢC|², and for LOCKED max wᵢ and Σ|∇ᵢC|², in one pass.
    let mut weighted_norm = V::Real::ZERO;
    let mut norm = V::Real::ZERO;
    let mut heaviest = V::Real::ZERO;
    for (w, g) in weights.iter().zip(&evaluation.gradients) {
        let squared = g.length_squared();
        weighted_norm += *w * squared;
        norm += squared;
        heaviest = V::Real::select(w.gt(heaviest), *w, heaviest);
    }
    let locked = weighted_norm.le(V::Real::from_f64(LOCKED) * heaviest * norm);
    let skipped =
        evaluation.degenerate | !weighted_norm.gt(V::Real::ZERO) | !weighted_norm.finite() | locked;
    let delta_lambda = match rule {
        Rule::Xpbd { alpha_tilde } => {
            (-evaluation.value - alpha_tilde * lambda) / (weighted_norm + alpha_tilde)
        }
        Rule::Pbd { k } => k * -evaluation.value / weighted_norm,
    };
    let delta_lambda = V::Real::select(skipped, V::Real::ZERO, delta_lambda);
    let mut delta_x = [V::ZERO; N];
    for ((dx, g), w) in delta_x.iter_mut().zip(&evaluation.gradients).zip(weights) {
        *dx = V::select(skipped, V::ZERO, *g * (w * delta_lambda));
    }
    (
        skipped,
        Correction {
            delta_lambda,
            delta_x,
        },
    )
}

/// One rigid XPBD projection of a constraint at `points` with rest value `rest` and inverse
/// masses `weights`, starting from λ = 0: Δx per particle (zero when skipped). The kernel the
/// solvers run per constraint, for benchmarks (`core/benches/kernels.rs`).
pub fn project_kernel<V: Vector3, const N: usize>(
    evaluate: impl Fn(&[V; N], V::Real) -> Evaluation<V, N>,
    points: &[V; N],
    rest: V::Real,
    weights: [V::Real; N],
) -> [V; N] {
    let rule = Rule::Xpbd {
        alpha_tilde: V::Real::ZERO,
    };
    correction_lanes(evaluate(points, rest), weights, V::Real::ZERO, rule)
        .1
        .delta_x
}

/// Below this fraction of max wᵢ · Σ|∇ᵢC|², Σ wᵢ|∇ᵢC|² says that the particles free to move
/// (w > 0) can barely change the constraint: those that could are pinned or held, and the free
/// ones' gradients nearly vanish. Projecting it would move a free particle by about |C| / |∇ᵢC|,
/// unboundedly far as ∇ᵢC → 0 (a face vertex of a height constraint whose other corners are
/// held flings out by millions of metres, and the next projections feed on it). At this
/// threshold a projection moves no particle more than 1/√LOCKED = 100 times as far as it would
/// with every particle free; at or below it the constraint is skipped, like a degenerate one:
/// Σ wᵢ|∇ᵢC|² ≤ LOCKED · max wᵢ · Σ|∇ᵢC|².
pub const LOCKED: f64 = 1e-4;

/// Σ wᵢ |∇ₚᵢC|², the denominator of every projection.
#[inline]
fn weighted_norm<V: Vector3, const N: usize>(
    weights: &[V::Real; N],
    gradients: &[V; N],
) -> V::Real {
    let mut sum = V::Real::ZERO;
    for (w, g) in weights.iter().zip(gradients) {
        sum += *w * g.length_squared();
    }
    sum
}

/// A particle held by the user.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grab {
    /// The particle.
    pub particle: usize,
    /// Where the user holds it.
    pub target: DVec3,
    target_at_last_step: DVec3,
    /// How fast the target moved over the last step.
    pub target_velocity: DVec3,
    lambda: f64,
}

/// The soft body in motion.
#[derive(Clone, Debug)]
pub struct Simulation {
    settings: Settings,
    rest_positions: Vec<DVec3>,
    positions: Vec<DVec3>,
    previous: Vec<DVec3>,
    velocities: Vec<DVec3>,
    /// Inverse masses from the lumped masses, 0 where pinned.
    inverse_masses: Vec<f64>,
    pinned: Vec<bool>,
    lumped_inverse_masses: Vec<f64>,
    tets: Vec<[u32; 4]>,
    /// Edge distance constraints.
    pub edges: ConstraintSet<2>,
    /// Height constraints: four per tet, tet t's at 4t..4t+4.
    pub planes: ConstraintSet<4>,
    /// Signed volume constraints, one per tet, in tet order.
    pub volumes: ConstraintSet<4>,
    grab: Option<Grab>,
    /// Δp of the last substep; during a substep, the predicted positions.
    corrections: Vec<DVec3>,
    /// The mean rest edge length, the scale of "settled".
    mean_edge: f64,
    /// Frames an edit has been settling, `None` when none is; see [`Settings::settle_edits`].
    settling: Option<u32>,
    frame: u64,
    time: f64,
}

impl Simulation {
    /// A simulation of `scene` at rest, with masses lumped from density × rest volume / 4 per tet.
    pub fn new(scene: &Scene, settings: Settings) -> Simulation {
        let mesh = &scene.mesh;
        let positions = mesh.positions.clone();
        let edges = ConstraintSet::new(mesh.edges(), &positions, distance::evaluate);
        let plane_particles = mesh
            .tets
            .iter()
            .flat_map(|t| plane::tet_vertex_order().map(|order| order.map(|k| t[k])))
            .collect();
        let planes = ConstraintSet::new(plane_particles, &positions, plane::evaluate);
        let volumes = ConstraintSet::new(mesh.tets.clone(), &positions, volume::evaluate);
        let lumped_inverse_masses = lumped_inverse_masses(mesh, &volumes.rest);
        let mean_edge = if edges.is_empty() {
            1.0
        } else {
            edges.rest.iter().sum::<f64>() / edges.len() as f64
        };
        let mut pinned = vec![false; positions.len()];
        for &i in &scene.pinned {
            pinned[i as usize] = true;
        }
        let n = positions.len();
        let mut simulation = Simulation {
            settings,
            rest_positions: positions.clone(),
            previous: positions.clone(),
            positions,
            velocities: vec![DVec3::ZERO; n],
            inverse_masses: vec![0.0; n],
            pinned,
            lumped_inverse_masses,
            tets: mesh.tets.clone(),
            edges,
            planes,
            volumes,
            grab: None,
            corrections: vec![DVec3::ZERO; n],
            mean_edge,
            settling: None,
            frame: 0,
            time: 0.0,
        };
        simulation.update_inverse_masses();
        simulation
    }

    /// The settings in force.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Changes the settings; they apply from the next substep.
    pub fn set_settings(&mut self, settings: Settings) {
        self.settings = settings;
    }

    /// Current particle positions.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Rest positions (the scene as made).
    pub fn rest_positions(&self) -> &[DVec3] {
        &self.rest_positions
    }

    /// Current particle velocities.
    pub fn velocities(&self) -> &[DVec3] {
        &self.velocities
    }

    /// Δp of the last substep, per particle: the position after the constraint projections minus
    /// the predicted position. Zero after a perturbation or a reset, and for a particle placed by
    /// hand, until the next substep.
    pub fn corrections(&self) -> &[DVec3] {
        &self.corrections
    }

    /// Whether an edit is settling (see [`Settings::settle_edits`]).
    pub fn is_settling(&self) -> bool {
        self.settling.is_some()
    }

    /// The largest Δp per substep, in metres, at which an edit counts as settled:
    /// [`SETTLE_FRACTION`] × the mean rest edge length, plus g h², the correction that gravity
    /// alone causes in a body at rest on the ground.
    pub fn settle_tolerance(&self) -> f64 {
        let h = self.settings.dt / self.settings.substeps.max(1) as f64;
        SETTLE_FRACTION * self.mean_edge + self.settings.gravity.abs() * h * h
    }

    /// Inverse masses in use (0 for pinned or grabbed-rigidly particles).
    pub fn inverse_masses(&self) -> &[f64] {
        &self.inverse_masses
    }

    /// The tets, as indices into the positions.
    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// Frames stepped since the start.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Simulated time in seconds.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Ok while every coordinate and velocity component is finite and below [`SOUND_LIMIT`] in
    /// size; otherwise the first that is not. Within the input [`crate::limits`] only an
    /// instability leaves that range; front ends check after every frame and stop.
    pub fn check(&self) -> Result<(), Divergence> {
        Divergence::find(
            self.frame,
            (SOUND_LIMIT, SOUND_LIMIT),
            self.positions.iter().map(|p| p.to_array()),
            self.velocities.iter().map(|v| v.to_array()),
            |i| i,
        )
    }

    /// Whether [`Simulation::check`] finds nothing.
    pub fn is_sound(&self) -> bool {
        self.check().is_ok()
    }

    /// The bytes of memory the simulation's arrays take (their capacities).
    pub fn heap_bytes(&self) -> usize {
        fn bytes<T>(v: &Vec<T>) -> usize {
            v.capacity() * size_of::<T>()
        }
        fn set<const N: usize>(s: &ConstraintSet<N>) -> usize {
            bytes(&s.particles) + bytes(&s.rest) + bytes(&s.lambda)
        }
        bytes(&self.rest_positions)
            + bytes(&self.positions)
            + bytes(&self.previous)
            + bytes(&self.velocities)
            + bytes(&self.inverse_masses)
            + bytes(&self.pinned)
            + bytes(&self.lumped_inverse_masses)
            + bytes(&self.tets)
            + bytes(&self.corrections)
            + set(&self.edges)
            + set(&self.planes)
            + set(&self.volumes)
    }

    /// Whether particle `i` is pinned.
    pub fn is_pinned(&self, i: usize) -> bool {
        self.pinned[i]
    }

    /// Pins or frees particle `i`.
    pub fn set_pinned(&mut self, i: usize, pinned: bool) {
        self.pinned[i] = pinned;
        self.update_inverse_masses();
    }

    /// Applies a perturbation to the current positions and stops all motion.
    pub fn perturb(&mut self, perturbation: crate::scene::Perturbation) {
        let mesh = TetMesh {
            positions: self.rest_positions.clone(),
            tets: self.tets.clone(),
        };
        perturbation.apply(&mut self.positions, &mesh);
        self.stop();
        self.settling = Some(0);
    }

    /// Puts every particle at the given positions, at rest (e.g. a state computed elsewhere).
    pub fn set_positions(&mut self, positions: &[DVec3]) {
        self.positions.copy_from_slice(positions);
        self.stop();
    }

    /// Puts particle `i` at `position` at rest (a kinematic move, e.g. a drag while paused).
    pub fn place(&mut self, i: usize, position: DVec3) {
        self.positions[i] = position;
        self.previous[i] = position;
        self.velocities[i] = DVec3::ZERO;
        self.corrections[i] = DVec3::ZERO;
        self.settling = Some(0);
    }

    /// Back to the rest shape, at rest, at frame 0.
    pub fn reset(&mut self) {
        self.positions.copy_from_slice(&self.rest_positions);
        self.stop();
        self.settling = None;
        self.frame = 0;
        self.time = 0.0;
    }

    /// Zeroes every velocity and multiplier.
    fn stop(&mut self) {
        self.previous.copy_from_slice(&self.positions);
        self.velocities.fill(DVec3::ZERO);
        self.corrections.fill(DVec3::ZERO);
        for lambda in [
            &mut self.edges.lambda,
            &mut self.planes.lambda,
            &mut self.volumes.lambda,
        ] {
            lambda.fill(0.0);
        }
    }

    /// Starts holding particle `i` at `target`. With zero grab compliance the particle follows the
    /// target exactly (its inverse mass is 0 meanwhile); otherwise a compliant zero-length
    /// constraint pulls it.
    pub fn grab(&mut self, i: usize, target: DVec3) {
        self.release();
        self.grab = Some(Grab {
            particle: i,
            target,
            target_at_last_step: target,
            target_velocity: DVec3::ZERO,
            lambda: 0.0,
        });
        self.update_inverse_masses();
    }

    /// Moves the held target.
    pub fn move_grab(&mut self, target: DVec3) {
        if let Some(grab) = &mut self.grab {
            grab.target = target;
        }
    }

    /// The current grab, if any.
    pub fn grabbed(&self) -> Option<&Grab> {
        self.grab.as_ref()
    }

    /// Lets go: the particle's mass comes back, and it keeps the target's velocity over the last
    /// step so it can be thrown.
    pub fn release(&mut self) {
        if let Some(grab) = self.grab.take() {
            self.velocities[grab.particle] = grab.target_velocity;
            self.update_inverse_masses();
        }
    }

    fn rigid_grab(&self) -> Option<Grab> {
        self.grab.filter(|_| self.settings.grab_compliance <= 0.0)
    }

    fn update_inverse_masses(&mut self) {
        for i in 0..self.positions.len() {
            self.inverse_masses[i] = if self.pinned[i] {
                0.0
            } else {
                self.lumped_inverse_masses[i]
            };
        }
        if let Some(grab) = self.rigid_grab() {
            self.inverse_masses[grab.particle] = 0.0;
        }
    }

    /// Advances one frame: `substeps` substeps of Δt / substeps.
    pub fn step(&mut self) {
        self.update_inverse_masses();
        for _ in 0..self.settings.substeps.max(1) {
            self.substep();
        }
        if let Some(grab) = &mut self.grab {
            grab.target_velocity = (grab.target - grab.target_at_last_step) / self.settings.dt;
            grab.target_at_last_step = grab.target;
        }
        if let Some(frames) = self.settling {
            let largest = self.largest_correction();
            self.settling = (self.settings.settle_edits
                && largest > self.settle_tolerance()
                && frames + 1 < MAX_SETTLE_FRAMES)
                .then_some(frames + 1);
        }
        self.frame += 1;
        self.time += self.settings.dt;
    }

    /// One substep: predict, project every active family `iterations` times, update velocities.
    /// The same as [`Simulation::begin_substep`], then for each iteration every constraint of
    /// [`Simulation::projection_order`] through [`Simulation::project`] and
    /// [`Simulation::end_sweep`], then [`Simulation::end_substep`] — done here in tight loops.
    pub fn substep(&mut self) {
        let h = self.substep_length();
        self.begin_substep();
        for _ in 0..self.settings.iterations.max(1) {
            self.sweep(h);
        }
        self.end_substep();
    }

    /// h = Δt / substeps.
    pub fn substep_length(&self) -> f64 {
        self.settings.dt / self.settings.substeps.max(1) as f64
    }

    /// The first part of a substep: predict positions, and (XPBD) λ = 0 for every constraint.
    pub fn begin_substep(&mut self) {
        let h = self.substep_length();
        self.predict(h);
        for lambda in [
            &mut self.edges.lambda,
            &mut self.planes.lambda,
            &mut self.volumes.lambda,
        ] {
            lambda.fill(0.0);
        }
        if let Some(grab) = &mut self.grab {
            grab.lambda = 0.0;
        }
    }

    /// The end of one sweep, after the constraint families: the grab, then the ground y ≥ 0.
    pub fn end_sweep(&mut self) {
        let h = self.substep_length();
        self.project_soft_grab(h);
        if self.settings.ground {
            integrate::project_ground(&mut self.positions, &self.inverse_masses);
        }
    }

    /// The last part of a substep: Δp = x − predicted x, then velocities from the positions.
    pub fn end_substep(&mut self) {
        let h = self.substep_length();
        for (correction, p) in self.corrections.iter_mut().zip(&self.positions) {
            *correction = *p - *correction;
        }
        self.update_velocities(h, self.settings.settle_edits && self.settling.is_some());
    }

    /// The constraints one sweep projects, in order: every constraint of each active family
    /// (edges, then heights, then volumes), as (family, index in the family).
    pub fn projection_order(&self) -> impl Iterator<Item = (Family, usize)> + '_ {
        let active = self.settings.active;
        Family::ALL
            .into_iter()
            .filter(move |&f| active.get(f))
            .flat_map(move |f| (0..self.constraint_count(f)).map(move |c| (f, c)))
    }

    /// The constraints of `family` on tet `tet`, as indices in the family: its edges (six), its
    /// four heights, or its volume.
    pub fn tet_constraints(&self, tet: usize, family: Family) -> impl Iterator<Item = usize> + '_ {
        let corners = self.tets[tet];
        let edges = (family == Family::Distance)
            .then(|| {
                TET_EDGES.iter().filter_map(move |&(a, b)| {
                    let key = [corners[a].min(corners[b]), corners[a].max(corners[b])];
                    self.edges.particles.binary_search(&key).ok()
                })
            })
            .into_iter()
            .flatten();
        let heights = (family == Family::Plane)
            .then(|| 4 * tet..4 * tet + 4)
            .into_iter()
            .flatten();
        let volume = (family == Family::Volume).then_some(tet);
        edges.chain(heights).chain(volume)
    }

    /// Constraint projections one frame makes with the current settings: the active families'
    /// constraints × substeps × iterations.
    pub fn projections_per_frame(&self) -> u64 {
        self.settings.projections_per_frame(PerFamily {
            edges: self.edges.len(),
            plane: self.planes.len(),
            volume: self.volumes.len(),
        })
    }

    /// How many constraints `family` has.
    pub fn constraint_count(&self, family: Family) -> usize {
        match family {
            Family::Distance => self.edges.len(),
            Family::Plane => self.planes.len(),
            Family::Volume => self.volumes.len(),
        }
    }

    /// What projecting constraint `c` of `family` now would do, with the current λ and the rule
    /// (XPBD or PBD) of the current settings: C, ∇C, the inverse masses, Δλ and Δx.
    pub fn projection(&self, family: Family, c: usize) -> Projection {
        let rule = self.rule(family, self.substep_length());
        match family {
            Family::Distance => describe(
                family,
                c,
                &self.edges,
                &self.positions,
                &self.inverse_masses,
                rule,
                distance::evaluate,
            ),
            Family::Plane => describe(
                family,
                c,
                &self.planes,
                &self.positions,
                &self.inverse_masses,
                rule,
                plane::evaluate,
            ),
            Family::Volume => describe(
                family,
                c,
                &self.volumes,
                &self.positions,
                &self.inverse_masses,
                rule,
                volume::evaluate,
            ),
        }
    }

    /// Projects constraint `c` of `family` once, exactly as a sweep does.
    pub fn project(&mut self, family: Family, c: usize) {
        let rule = self.rule(family, self.substep_length());
        let (positions, w) = (&mut self.positions, &self.inverse_masses);
        match family {
            Family::Distance => {
                project_one(&mut self.edges, positions, w, rule, distance::evaluate, c)
            }
            Family::Plane => project_one(&mut self.planes, positions, w, rule, plane::evaluate, c),
            Family::Volume => {
                project_one(&mut self.volumes, positions, w, rule, volume::evaluate, c)
            }
        }
    }

    /// The longest Δp of the last substep among particles that can move.
    fn largest_correction(&self) -> f64 {
        self.corrections
            .iter()
            .zip(&self.inverse_masses)
            .filter(|(_, w)| **w > 0.0)
            .map(|(c, _)| c.length())
            .fold(0.0, f64::max)
    }

    fn predict(&mut self, h: f64) {
        integrate::predict(
            &mut self.positions,
            &mut self.previous,
            &mut self.velocities,
            &self.inverse_masses,
            self.settings.gravity,
            h,
            self.settings.ground,
        );
        if let Some(grab) = self.rigid_grab() {
            self.positions[grab.particle] = grab.target;
        }
        self.corrections.copy_from_slice(&self.positions);
    }

    pub(crate) fn rule(&self, family: Family, h: f64) -> Rule<f64> {
        Rule::for_settings(&self.settings, family, h)
    }

    /// One Gauss–Seidel sweep over the active families, then the grab, then the ground.
    fn sweep(&mut self, h: f64) {
        let active = self.settings.active;
        if active.edges {
            let rule = self.rule(Family::Distance, h);
            project_all(
                &mut self.edges,
                &mut self.positions,
                &self.inverse_masses,
                rule,
                distance::evaluate,
            );
        }
        if active.plane {
            let rule = self.rule(Family::Plane, h);
            project_all(
                &mut self.planes,
                &mut self.positions,
                &self.inverse_masses,
                rule,
                plane::evaluate,
            );
        }
        if active.volume {
            let rule = self.rule(Family::Volume, h);
            project_all(
                &mut self.volumes,
                &mut self.positions,
                &self.inverse_masses,
                rule,
                volume::evaluate,
            );
        }
        self.end_sweep();
    }

    fn project_soft_grab(&mut self, h: f64) {
        let compliance = self.settings.grab_compliance;
        let Some(grab) = self.grab.as_mut().filter(|_| compliance > 0.0) else {
            return;
        };
        let i = grab.particle;
        let evaluation = distance::evaluate(&[self.positions[i], grab.target], 0.0);
        let rule = Rule::Xpbd {
            alpha_tilde: compliance / (h * h),
        };
        if let Some(c) = correction(evaluation, [self.inverse_masses[i], 0.0], grab.lambda, rule) {
            grab.lambda += c.delta_lambda;
            self.positions[i] += c.delta_x[0];
        }
    }

    /// v = (x − x_prev) / h, damped; when `settling`, no faster than the predicted velocity.
    fn update_velocities(&mut self, h: f64, settling: bool) {
        integrate::update_velocities(
            &self.positions,
            &self.previous,
            &mut self.velocities,
            h,
            self.settings.damping,
            settling,
        );
    }
}

/// Projects every constraint of `set` once, in order (Gauss–Seidel).
#[inline]
fn project_all<const N: usize>(
    set: &mut ConstraintSet<N>,
    positions: &mut [DVec3],
    inverse_masses: &[f64],
    rule: Rule<f64>,
    evaluate: fn(&[DVec3; N], f64) -> Evaluation<DVec3, N>,
) {
    for c in 0..set.particles.len() {
        project_one(set, positions, inverse_masses, rule, evaluate, c);
    }
}

/// Projects constraint `c` of `set`: λ += Δλ, xᵢ += Δxᵢ.
#[inline]
fn project_one<const N: usize>(
    set: &mut ConstraintSet<N>,
    positions: &mut [DVec3],
    inverse_masses: &[f64],
    rule: Rule<f64>,
    evaluate: fn(&[DVec3; N], f64) -> Evaluation<DVec3, N>,
    c: usize,
) {
    let idx = set.particles[c];
    let evaluation = evaluate(&idx.map(|i| positions[i as usize]), set.rest[c]);
    let weights = idx.map(|i| inverse_masses[i as usize]);
    if let Some(correction) = correction(evaluation, weights, set.lambda[c], rule) {
        set.lambda[c] += correction.delta_lambda;
        for k in 0..N {
            positions[idx[k] as usize] += correction.delta_x[k];
        }
    }
}

/// One constraint, described for a reader: see [`Simulation::projection`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// The constraint's family.
    pub family: Family,
    /// Its index within the family.
    pub constraint: usize,
    /// Its particles; the first [`Projection::len`] are used (2 for an edge, 4 otherwise).
    pub particles: [u32; 4],
    /// How many particles it has.
    pub len: usize,
    /// C now.
    pub value: f64,
    /// The rest value, d or V.
    pub rest: f64,
    /// ∇ₚC for each particle.
    pub gradients: [DVec3; 4],
    /// The inverse mass w of each particle (0 if pinned or held).
    pub inverse_masses: [f64; 4],
    /// Σ wᵢ |∇ₚᵢC|².
    pub weighted_norm: f64,
    /// λ accumulated so far in this substep (XPBD).
    pub lambda: f64,
    /// XPBD: Δλ; PBD: k′ s. `None` when the projection is skipped (degenerate, every particle
    /// fixed, or [`LOCKED`]).
    pub delta_lambda: Option<f64>,
    /// Δx the projection would give each particle (zero when skipped).
    pub delta_x: [DVec3; 4],
    /// Whether ∇C is undefined here.
    pub degenerate: bool,
}

impl Projection {
    /// The particles it uses.
    pub fn particles(&self) -> &[u32] {
        &self.particles[..self.len]
    }
}

/// [`Projection`] of constraint `c` of `set`.
fn describe<const N: usize>(
    family: Family,
    c: usize,
    set: &ConstraintSet<N>,
    positions: &[DVec3],
    inverse_masses: &[f64],
    rule: Rule<f64>,
    evaluate: fn(&[DVec3; N], f64) -> Evaluation<DVec3, N>,
) -> Projection {
    let idx = set.particles[c];
    let evaluation = evaluate(&idx.map(|i| positions[i as usize]), set.rest[c]);
    let weights = idx.map(|i| inverse_masses[i as usize]);
    let correction = correction(evaluation, weights, set.lambda[c], rule);
    let mut projection = Projection {
        family,
        constraint: c,
        particles: [0; 4],
        len: N,
        value: evaluation.value,
        rest: set.rest[c],
        gradients: [DVec3::ZERO; 4],
        inverse_masses: [0.0; 4],
        weighted_norm: weighted_norm(&weights, &evaluation.gradients),
        lambda: set.lambda[c],
        delta_lambda: correction.map(|c| c.delta_lambda),
        delta_x: [DVec3::ZERO; 4],
        degenerate: evaluation.degenerate,
    };
    for k in 0..N {
        projection.particles[k] = idx[k];
        projection.gradients[k] = evaluation.gradients[k];
        projection.inverse_masses[k] = weights[k];
        if let Some(correction) = &correction {
            projection.delta_x[k] = correction.delta_x[k];
        }
    }
    projection
}

/// 1 / Σ (density × V₀ / 4) over the tets at each particle. A particle whose tets all have zero
/// rest volume gets the mean mass, so it still moves.
fn lumped_inverse_masses(mesh: &TetMesh, rest_volumes: &[f64]) -> Vec<f64> {
    let mut masses = vec![0.0; mesh.positions.len()];
    for (tet, &v) in mesh.tets.iter().zip(rest_volumes) {
        for &i in tet {
            masses[i as usize] += DENSITY * v.abs() / 4.0;
        }
    }
    let positive: Vec<f64> = masses.iter().copied().filter(|&m| m > 0.0).collect();
    let mean = if positive.is_empty() {
        1.0
    } else {
        positive.iter().sum::<f64>() / positive.len() as f64
    };
    masses
        .iter()
        .map(|&m| 1.0 / if m > 0.0 { m } else { mean })
        .collect()
}
