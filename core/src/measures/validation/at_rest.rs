//! How a static case is run: XPBD on the neo-Hookean pair with at least 4 iterations (at one
//! iteration XPBD is far from converged, and a static answer is off by up to 25 %:
//! docs/experiments.md, table 13), damped, until no particle moves faster than a stop speed.
//!
//! Damping removes a fraction d·h of each velocity every substep: it changes how a body comes to
//! rest, never where, since a body at rest has no velocity to damp. The stop speed is stated per
//! case as a fraction of the deformation it measures, so "at rest" means the same for every
//! case: the remaining motion moves the measured value by less than its tolerance.

use super::{Check, Stop, Trial};
use crate::constraints::material::Material;
use crate::constraints::{Family, PerFamily};
use crate::simulation::{DENSITY, Method, Settings, Simulation};
use glam::DVec3;

/// A static run's protocol.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct AtRest {
    /// Substeps per frame (at least the material's stable count, [`AtRest::settings`]).
    pub substeps: u32,
    /// XPBD iterations per substep, at least 4.
    pub iterations: u32,
    /// Velocity damping per second.
    pub damping: f64,
    /// At rest: no particle moved further than this times Δt over the last frame (m/s).
    pub stop_speed: f64,
    /// The most frames the run may take to come to rest.
    pub max_frames: u32,
}

impl AtRest {
    /// The settings of a static run on `scene`'s simulation: XPBD, the neo-Hookean pair of
    /// `material`, gravity `gravity` (the ground with it), and at least the substeps that keep
    /// the material stable on a mesh whose shortest edge is `shortest_edge`
    /// ([`Material::substeps_needed`]).
    pub(super) fn settings(
        &self,
        material: Material,
        gravity: f64,
        shortest_edge: f64,
    ) -> Settings {
        assert!(
            self.iterations >= 4,
            "a static case runs at least 4 iterations"
        );
        let mut settings = Settings {
            method: Method::Xpbd,
            active: neohookean(),
            iterations: self.iterations,
            damping: self.damping,
            ..Settings::default()
        };
        settings.material = material;
        settings.set_gravity(gravity);
        let needed = material.substeps_needed(settings.dt, shortest_edge, DENSITY);
        settings.substeps = self.substeps.max(needed.min(u32::MAX as u64) as u32);
        settings
    }

    /// "XPBD 100 × 4, damping 10/s".
    pub(super) fn describe(&self, settings: &Settings) -> String {
        format!(
            "XPBD {} × {}, damping {}/s",
            settings.substeps, settings.iterations, self.damping
        )
    }

    /// Steps `simulation` until it is at rest, or [`AtRest::max_frames`]: until no particle has
    /// moved faster than the stop speed in any frame of a window that spans the body's slowest
    /// period (at least 10 frames). A single frame would not do: at an oscillation's turning
    /// point every particle is slow whatever the amplitude, and a run stopped there is off by the
    /// amplitude. Over a period an oscillation of amplitude A reaches A ω, so what the window lets
    /// through is below stop speed / ω.
    ///
    /// The slowest period is Rayleigh's estimate from the exact static solution u of the case's
    /// discrete problem (its displacement under the load, close to the first mode's shape):
    /// ω² = f·u / uᵀMu, f the load, M the lumped masses. Without a load it is the least window.
    ///
    /// Speed is measured over a frame: the largest distance a particle moved in the last frame,
    /// divided by Δt. A substep's velocity (x − x_prev) / h would not do on the fast engine:
    /// each projection rounds a position to f32 (an ulp, 6·10⁻⁸ m at 1 m), and divided by
    /// h = 1/6000 s that is a jitter of 4·10⁻⁴ m/s that never goes away. Over a frame the jitter
    /// does not add up, and its floor is an ulp / Δt, 4·10⁻⁶ m/s; that floor is why the stop
    /// speed is at least [`AtRest::stop_speed_for`]'s.
    pub(super) fn run(&self, trial: &mut Trial, simulation: &mut Simulation) -> Result<Rest, Stop> {
        self.run_watching(trial, simulation, |_| {})
    }

    /// [`AtRest::run`], with `on_frame` shown the simulation after every frame.
    pub(super) fn run_watching(
        &self,
        trial: &mut Trial,
        simulation: &mut Simulation,
        mut on_frame: impl FnMut(&Simulation),
    ) -> Result<Rest, Stop> {
        let exact = if is_static_problem(simulation) {
            super::discrete::exact(simulation)
        } else {
            Err("the case has neither a load nor a held particle".to_owned())
        };
        let period = exact
            .as_ref()
            .ok()
            .and_then(|exact| slowest_period(simulation, exact));
        let dt = simulation.settings().dt;
        let window = period.map_or(MIN_WINDOW, |t| MIN_WINDOW.max((t / dt).ceil() as u32));
        let mut before = simulation.positions().to_vec();
        let stop_speed = self.stop_speed_for(simulation);
        let (mut speed, mut slow_frames) = (f64::INFINITY, 0);
        for frame in 1..=self.max_frames {
            trial.step(simulation)?;
            on_frame(simulation);
            let now = frame_speed(simulation, &before);
            before.copy_from_slice(simulation.positions());
            slow_frames = if now < stop_speed { slow_frames + 1 } else { 0 };
            // The largest speed of the window ending here.
            speed = if slow_frames == 1 {
                now
            } else {
                speed.max(now)
            };
            if slow_frames >= window {
                return Ok(Rest {
                    frames: frame,
                    speed,
                    stop_speed,
                    window,
                    at_rest: true,
                    exact,
                });
            }
        }
        Ok(Rest {
            frames: self.max_frames,
            speed,
            stop_speed,
            window,
            at_rest: false,
            exact,
        })
    }

    /// The stop speed on `simulation`'s engine: [`AtRest::stop_speed`], or what its precision
    /// can resolve if that is more, 4 ε X / Δt with ε the machine epsilon of its positions
    /// (f32's 1.2·10⁻⁷ on the fast engine) and X the largest coordinate: four ulps a frame.
    pub(super) fn stop_speed_for(&self, simulation: &Simulation) -> f64 {
        let epsilon = match simulation.engine() {
            crate::simulation::EngineChoice::Fast => f32::EPSILON as f64,
            _ => f64::EPSILON,
        };
        let extent = simulation
            .positions()
            .iter()
            .map(|p| p.abs().max_element())
            .fold(0.0, f64::max);
        self.stop_speed
            .max(4.0 * epsilon * extent / simulation.settings().dt)
    }
}

/// The least window of frames a run must stay below its stop speed.
const MIN_WINDOW: u32 = 10;

/// Whether `simulation`'s body has a static solution to compare with: a load (gravity or an
/// external force) or a held particle.
fn is_static_problem(simulation: &Simulation) -> bool {
    simulation.settings().gravity != 0.0
        || simulation.forces().iter().any(|f| *f != DVec3::ZERO)
        || simulation.inverse_masses().iter().any(|&w| w <= 0.0)
}

/// Rayleigh's estimate of the slowest period of `simulation`'s body about the static solution
/// `exact` (s): 2π / ω with ω² = f·u / uᵀMu, u the displacement of `exact` from the rest
/// shape, f the load (gravity on the lumped masses, the external forces). `None` where u is 0.
///
/// For a load that excites the first mode, u is close to its shape and the estimate close to
/// its period (within a few per cent for a cantilever under its weight); it is never longer.
fn slowest_period(simulation: &Simulation, exact: &[DVec3]) -> Option<f64> {
    let body = simulation.body();
    let gravity = simulation.settings().gravity;
    let (mut work, mut inertia) = (0.0, 0.0);
    for (i, (x, rest)) in exact.iter().zip(&body.rest_positions).enumerate() {
        if simulation.inverse_masses()[i] <= 0.0 {
            continue;
        }
        let mass = 1.0 / body.lumped_inverse_masses[i];
        let u = *x - *rest;
        let force = DVec3::new(0.0, -gravity * mass, 0.0)
            + body.forces.get(i).copied().unwrap_or(DVec3::ZERO);
        work += force.dot(u);
        inertia += mass * u.length_squared();
    }
    (work > 0.0 && inertia > 0.0).then(|| std::f64::consts::TAU / (work / inertia).sqrt())
}

/// How a static run ended.
#[derive(Clone, Debug)]
pub(super) struct Rest {
    /// Frames stepped.
    pub frames: u32,
    /// The largest frame speed of the last window (of the run's frames when it did not come to
    /// rest), m/s ([`frame_speed`]).
    pub speed: f64,
    /// The frames it had to stay below the stop speed: the slowest period.
    pub window: u32,
    /// The exact solution of the case's discrete problem, or why there is none.
    pub exact: Result<Vec<DVec3>, String>,
    /// The stop speed it was held to ([`AtRest::stop_speed_for`]).
    pub stop_speed: f64,
    /// Whether it came below the stop speed.
    pub at_rest: bool,
}

impl Rest {
    /// The check that the run came to rest, labelled with `what` and the protocol.
    pub(super) fn check(&self, what: &str, protocol: &AtRest, settings: &Settings) -> Check {
        Check {
            criterion: format!("at rest within {} frames", protocol.max_frames),
            passed: Some(self.at_rest),
            ..Check::at_most(
                format!(
                    "{what}: largest frame speed over the last {} frames (the slowest period), \
                     after {} frames ({})",
                    self.window,
                    self.frames,
                    protocol.describe(settings)
                ),
                self.stop_speed,
                "the stop speed, or 4 ulps of the positions a frame if more",
                self.speed,
            )
        }
    }
}

/// The Courant number of a static run: c h / Δx, with c the material's pressure wave speed, h
/// the substep, Δx the cell size. XPBD's static bias, its answer at rest against the exact
/// solution of the same discrete problem, grows as its square (docs/experiments.md, "Whose error
/// it is").
pub(super) fn courant(settings: &Settings, material: Material, cell: f64) -> f64 {
    let h = settings.dt / settings.substeps.max(1) as f64;
    material.wave_speed(DENSITY) * h / cell
}

/// The neo-Hookean pair, and nothing else.
pub(super) fn neohookean() -> PerFamily<bool> {
    PerFamily::builtin_from_fn(|f| {
        f == Family::NEOHOOKEAN_DEVIATORIC || f == Family::NEOHOOKEAN_HYDROSTATIC
    })
}

/// The largest distance a particle moved since `before`, over one frame's length: m/s.
pub(super) fn frame_speed(simulation: &Simulation, before: &[glam::DVec3]) -> f64 {
    simulation
        .positions()
        .iter()
        .zip(before)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f64::max)
        / simulation.settings().dt
}

/// The number of particle (i, j, k) of a [`crate::scene::lattice`] of `cells`.
pub(super) fn lattice_index(cells: [usize; 3], i: usize, j: usize, k: usize) -> usize {
    let [_, ny, nz] = cells;
    (i * (ny + 1) + j) * (nz + 1) + k
}

/// The particles of the plane `axis` = `index` of a [`crate::scene::lattice`] of `cells`
/// (axis 0, 1, 2 for x, y, z), in lattice order.
pub(super) fn lattice_plane(cells: [usize; 3], axis: usize, index: usize) -> Vec<usize> {
    let mut plane = Vec::new();
    for i in 0..=cells[0] {
        for j in 0..=cells[1] {
            for k in 0..=cells[2] {
                if [i, j, k][axis] == index {
                    plane.push(lattice_index(cells, i, j, k));
                }
            }
        }
    }
    plane
}

/// The mean of `values` (NaN when there are none).
pub(super) fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    sum / n as f64
}
