//! Abuse runs: both engines driven through 10⁴ frames each of random edits (drags held and
//! thrown, particles placed anywhere in an arena three times the body's size around the body,
//! tets inverted, mirror, flatten, scramble, pins, resets) and random settings anywhere within
//! their ranges of `tetlab_core::input::limits` (substeps × iterations kept to at most 400 so that a
//! run takes seconds).
//!
//! The run is a sequence of stretches. Each starts afresh (the rest shape, nothing pinned or
//! held), draws new settings, makes one to three edits, then runs [`QUIET`] frames without
//! edits. After every frame:
//! - no NaN, in any state: every position and velocity is a number;
//! - nothing beyond the engine's range (positions, velocities and every metric:
//!   `Metrics::measure_sound`, `Simulation::check`, which asks the fast solver too). The one exception is documented in
//!   docs/reliability.md: a launch (below) can carry the f32 engine's particles past its 10⁹ m,
//!   which it reports as a divergence; the stretch then ends;
//! - nothing blows up. Motion has sources: an edit, and the projections that undo it or undo the
//!   body's stretch, move a particle by about the arena (or the body's extent) in a substep, and
//!   v = Δx / h turns that into speed (a launch; the workbench's "settle edits" caps it); a throw
//!   gives the held particle the hand's speed; gravity adds |g| Δt per frame; an impact can turn
//!   the motion of the whole body into motion of its parts. The largest of these since the
//!   stretch began is the speed put in, and no particle may move, relative to the centre of
//!   mass, more than [`BOUND`] times as fast. An unstable solver grows without bound.
//!
//! `cargo test --release -p tetlab-core --test abuse -- --nocapture` prints the figures that
//! docs/reliability.md quotes.

use glam::DVec3;
use tetlab_core::constraints::Family;
use tetlab_core::constraints::material::{self, Material};
use tetlab_core::input::limits::{self, Bounds};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::numbers::random::SplitMix64;
use tetlab_core::scene::{Builtin, Perturbation, Scene, reflect_through_opposite_face};
use tetlab_core::simulation::fast::FastSimulation;
use tetlab_core::simulation::{DENSITY, EngineChoice, Method, Settings, Simulation};

/// Frames per engine.
const FRAMES: usize = 10_000;
/// Frames of a stretch without edits (a burst of edits comes before each).
const QUIET: usize = 40;
/// How many times the speed put in a particle may reach before it counts as blowing up.
const BOUND: f64 = 10.0;
/// Substeps × iterations stay at or below this (each is drawn from its whole range first).
const MOST_SWEEPS: u32 = 400;

/// A number drawn log-uniformly from `bounds` (or one of its ends, one time in five).
fn log_uniform(rng: &mut SplitMix64, bounds: &Bounds<f64>, smallest: f64) -> f64 {
    match rng.next_u64() % 10 {
        0 => bounds.min,
        1 => bounds.max,
        _ => rng
            .range(bounds.min.max(smallest).ln(), bounds.max.ln())
            .exp(),
    }
}

/// A whole number drawn log-uniformly from `bounds`.
fn whole(rng: &mut SplitMix64, bounds: &Bounds<u32>) -> u32 {
    let x = rng.range(0.0, (bounds.max as f64 + 1.0).ln()).exp() as u32;
    x.clamp(bounds.min, bounds.max)
}

/// Settings anywhere within their ranges.
fn random_settings(rng: &mut SplitMix64) -> Settings {
    let coin = |rng: &mut SplitMix64| rng.next_u64().is_multiple_of(2);
    let mut settings = Settings {
        method: if coin(rng) { Method::Xpbd } else { Method::Pbd },
        dt: log_uniform(rng, &limits::DT, limits::DT.min),
        damping: if coin(rng) {
            0.0
        } else {
            log_uniform(rng, &limits::DAMPING, 1e-3)
        },
        grab_compliance: if coin(rng) {
            0.0
        } else {
            log_uniform(rng, &limits::COMPLIANCE, 1e-9)
        },
        settle_edits: coin(rng),
        ..Settings::default()
    };
    loop {
        settings.substeps = whole(rng, &limits::SUBSTEPS);
        settings.iterations = whole(rng, &limits::ITERATIONS);
        if settings.substeps * settings.iterations <= MOST_SWEEPS {
            break;
        }
    }
    let gravity = match rng.next_u64() % 4 {
        0 => 0.0,
        1 => rng.range(limits::GRAVITY.min, limits::GRAVITY.max),
        _ => rng.range(-20.0, 20.0),
    };
    settings.set_gravity(gravity);
    settings.ground = settings.ground && !rng.next_u64().is_multiple_of(4);
    for family in
        Family::builtins().filter(|f| f.builtin_row().unwrap().compliance_from_material.is_none())
    {
        settings
            .active
            .set(family, !rng.next_u64().is_multiple_of(3));
        let alpha = if rng.next_u64().is_multiple_of(3) {
            0.0
        } else {
            log_uniform(rng, &limits::COMPLIANCE, 1e-12)
        };
        settings.compliance.set(family, alpha);
        settings.stiffness.set(family, rng.next_f64());
    }
    // The families a material describes: on or off together, as the command line and the
    // workbench have them, with any material in range.
    let on = !rng.next_u64().is_multiple_of(3);
    for family in
        Family::builtins().filter(|f| f.builtin_row().unwrap().compliance_from_material.is_some())
    {
        settings.active.set(family, on);
    }
    // Within the material's documented stable range (Material::substeps_needed) on the
    // arena's cube.
    let poisson = rng.range(0.0, material::MAX_POISSON);
    let h = settings.dt / settings.substeps as f64;
    let unit = Material {
        young: 1.0,
        poisson,
    };
    let edge = Simulation::new(&cube(), Settings::default()).shortest_edge();
    let stiffest = (material::STABLE_COURANT * edge / h / unit.wave_speed(DENSITY)).powi(2);
    let bounds = Bounds {
        max: stiffest.clamp(material::YOUNG.min, material::YOUNG.max),
        ..material::YOUNG
    };
    settings.material = Material {
        young: log_uniform(rng, &bounds, bounds.min),
        poisson,
    };
    settings.check().expect("drawn within the limits");
    settings
}

/// Whether the particles that cannot move (inverse mass 0: pinned, or held rigidly) are farther
/// apart than `width`, the rest body's diameter: no shape of the body then satisfies its
/// constraints.
fn held_apart(positions: &[DVec3], inverse_masses: &[f64], width: f64) -> bool {
    let fixed: Vec<DVec3> = (0..positions.len())
        .filter(|&i| inverse_masses[i] == 0.0)
        .map(|i| positions[i])
        .collect();
    let (lo, hi) = bounds(&fixed);
    fixed.len() > 1 && (hi - lo).length() > width
}

/// The box every edit stays in: three times the rest body's size, around where the body is now
/// (a hand reaches for the body where it is).
struct Arena {
    size: f64,
    /// The rest body's diameter.
    width: f64,
}

impl Arena {
    fn new(rest: &[DVec3]) -> Arena {
        let (lo, hi) = bounds(rest);
        let width = (hi - lo).length();
        Arena {
            size: 3.0 * width,
            width,
        }
    }

    /// A point of the arena around the body at `positions`, above the ground.
    fn point(&self, positions: &[DVec3], rng: &mut SplitMix64) -> DVec3 {
        let (lo, hi) = bounds(positions);
        let mut p = (lo + hi) / 2.0 + rng.in_cube(self.size / 2.0);
        p.y = p.y.max(0.0);
        p
    }
}

fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    let lo = points.iter().fold(DVec3::INFINITY, |a, &b| a.min(b));
    let hi = points.iter().fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
    (lo, hi)
}

/// The motion of a state: the centre of mass's speed, the fastest particle relative to it, and
/// the farthest particle from it (the centre weighted by mass; pinned and held particles, whose
/// inverse mass is 0, left out).
struct Motion {
    centre_speed: f64,
    internal_speed: f64,
    extent: f64,
}

impl Motion {
    fn of(positions: &[DVec3], velocities: &[DVec3], inverse_masses: &[f64]) -> Motion {
        let free: Vec<usize> = (0..positions.len())
            .filter(|&i| inverse_masses[i] > 0.0)
            .collect();
        let mass: f64 = free.iter().map(|&i| 1.0 / inverse_masses[i]).sum();
        let centre = |values: &[DVec3]| {
            free.iter()
                .map(|&i| values[i] / inverse_masses[i])
                .sum::<DVec3>()
                / mass.max(f64::MIN_POSITIVE)
        };
        let (x, v) = (centre(positions), centre(velocities));
        let farthest = |values: &[DVec3], c: DVec3| {
            free.iter()
                .map(|&i| values[i].distance(c))
                .fold(0.0, f64::max)
        };
        Motion {
            centre_speed: v.length(),
            internal_speed: farthest(velocities, v),
            extent: farthest(positions, x),
        }
    }
}

/// The speed put in since the stretch began, and the largest figures a run reached.
#[derive(Debug, Default)]
struct Watch {
    frames: usize,
    edits: usize,
    stretches: usize,
    /// The speed put in since the stretch began, m/s.
    speed_in: f64,
    /// The largest internal speed relative to the speed put in.
    ratio: f64,
    /// The largest internal speed, m/s.
    fastest: f64,
    /// Stretches whose fixed particles were held apart (no shape satisfies the constraints).
    held_apart: usize,
    /// Launches that carried the f32 engine past its range.
    out_of_range: usize,
}

impl Watch {
    /// A new stretch: nothing put in yet.
    fn start_afresh(&mut self) {
        self.speed_in = 0.0;
    }

    /// Takes in what can speed the body up in the frame to come, from the state `before` it: the
    /// correction that undoes an edit or the body's stretch, per substep; the hand's speed;
    /// gravity over the frame; the body's own speed.
    fn put_in(&mut self, settings: &Settings, arena: &Arena, hand: f64, before: &Motion) {
        let h = settings.dt / settings.substeps as f64;
        let sources = [
            arena.size.max(before.extent) / h,
            hand,
            settings.gravity.abs() * settings.dt,
            before.centre_speed,
        ];
        self.speed_in = sources.into_iter().fold(self.speed_in, f64::max);
    }

    /// Checks the state after a frame; `what` says where, when it fails.
    fn check(&mut self, motion: &Motion, settings: &Settings, what: &str) {
        self.frames += 1;
        let ratio = motion.internal_speed / self.speed_in;
        assert!(
            ratio <= BOUND,
            "{what}: particles move {ratio} times faster than the {} m/s put in; {settings:?}",
            self.speed_in
        );
        self.ratio = self.ratio.max(ratio);
        self.fastest = self.fastest.max(motion.internal_speed);
    }

    fn print(&self, engine: &str) {
        println!(
            "{engine}: {} frames in {} stretches after {} edits; the fastest particle \
             {:.2e} m/s relative to the centre of mass, at most {:.3} times the speed put in; \
             {} stretches with the fixed particles held apart; {} launches past the f32 range",
            self.frames,
            self.stretches,
            self.edits,
            self.fastest,
            self.ratio,
            self.held_apart,
            self.out_of_range
        );
    }
}

/// One random edit of the kinds the workbench offers (grabs only where the engine has them).
/// Returns the hand's speed when the edit let go of a held particle (a throw).
fn random_edit(
    simulation: &mut Simulation,
    rng: &mut SplitMix64,
    arena: &Arena,
    grabs: bool,
) -> f64 {
    let n = simulation.positions().len();
    let particle = (rng.next_u64() % n as u64) as usize;
    match rng.next_u64() % if grabs { 10 } else { 7 } {
        0 => simulation.perturb(Perturbation::Mirror),
        1 => simulation.perturb(Perturbation::Flatten),
        2 => simulation.perturb(Perturbation::Scramble(rng.next_u64())),
        3 => {
            let tets = simulation.tets().len();
            let corners = simulation.tets()[(rng.next_u64() % tets as u64) as usize];
            let k = (rng.next_u64() % 4) as usize;
            let mut positions = simulation.positions().to_vec();
            reflect_through_opposite_face(&mut positions, &corners, k);
            let i = corners[k] as usize;
            simulation.place(i, positions[i]);
        }
        4 => {
            let target = arena.point(simulation.positions(), rng);
            simulation.place(particle, target);
        }
        5 => {
            let pinned = simulation.is_pinned(particle);
            simulation.set_pinned(particle, !pinned);
        }
        6 => simulation.reset(),
        7 => {
            let target = arena.point(simulation.positions(), rng);
            simulation.grab(particle, target);
        }
        8 => {
            let target = arena.point(simulation.positions(), rng);
            simulation.move_grab(target);
        }
        _ => {
            let hand = simulation
                .grabbed()
                .map_or(0.0, |grab| grab.target_velocity.length());
            simulation.release();
            return hand;
        }
    }
    0.0
}

/// The run's seed: `default`, or `TETLAB_ABUSE_SEED` to explore others.
fn seed(default: u64) -> u64 {
    std::env::var("TETLAB_ABUSE_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn cube() -> Scene {
    Scene::builtin(Builtin::Cube, 2).unwrap()
}

/// Not even a diverging state may hold a NaN: every value beyond the range stays a number, which
/// the divergence message can name.
#[track_caller]
fn assert_no_nan(positions: &[DVec3], velocities: &[DVec3], frame: usize) {
    assert!(
        positions.iter().chain(velocities).all(|v| !v.is_nan()),
        "frame {frame}: NaN in the state"
    );
}

/// A fresh start: the rest shape, nothing pinned or held.
fn start_afresh(simulation: &mut Simulation, watch: &mut Watch) {
    simulation.release();
    for i in 0..simulation.positions().len() {
        simulation.set_pinned(i, false);
    }
    simulation.reset();
    watch.start_afresh();
}

fn motion_of(simulation: &Simulation) -> Motion {
    Motion::of(
        simulation.positions(),
        simulation.velocities(),
        simulation.inverse_masses(),
    )
}

/// 10⁴ frames of stretches on `engine` ([`EngineChoice::Fast`] or the reference one), drawn from
/// `seed`, through the [`Simulation`] the product drives: edits and grabs on the simulation's
/// arrays (the fast solver takes them up before its next frame, on one or two threads). On the
/// fast engine a launch may carry particles past its 10⁹ m (docs/reliability.md): the stretch then
/// ends, is counted, and must have been one the speed put in allows.
fn survives_random_edits_grabs_and_settings(engine: EngineChoice, seed: u64, name: &str) {
    let scene = cube();
    let arena = Arena::new(&scene.mesh.positions);
    let mut rng = SplitMix64::new(seed);
    let mut simulation = Simulation::new(&scene, Settings::default());
    let mut watch = Watch::default();
    while watch.frames < FRAMES {
        start_afresh(&mut simulation, &mut watch);
        watch.stretches += 1;
        simulation.set_settings(Settings {
            engine,
            ..random_settings(&mut rng)
        });
        if engine == EngineChoice::Fast {
            simulation.set_threads(1 + (rng.next_u64() % 2) as usize);
        }
        let before = motion_of(&simulation);
        let mut hand = 0.0;
        for _ in 0..1 + rng.next_u64() % 3 {
            hand = f64::max(hand, random_edit(&mut simulation, &mut rng, &arena, true));
            watch.edits += 1;
        }
        if held_apart(
            simulation.positions(),
            simulation.inverse_masses(),
            arena.width,
        ) {
            watch.held_apart += 1;
        }
        let settings = *simulation.settings();
        // The hand that holds a particle moved it with the edits, at the speed put in then.
        let grip = simulation
            .grabbed()
            .map_or(0.0, |g| g.target_velocity.length());
        watch.put_in(&settings, &arena, hand.max(grip), &before);
        for _ in 0..QUIET {
            let before = motion_of(&simulation);
            watch.put_in(&settings, &arena, 0.0, &before);
            simulation.step();
            assert_no_nan(
                simulation.positions(),
                simulation.velocities(),
                watch.frames,
            );
            let what = format!("frame {}", watch.frames);
            if let Err(divergence) = Metrics::measure_sound(&simulation) {
                assert!(
                    engine == EngineChoice::Fast,
                    "{what}: {divergence}; {settings:?}"
                );
                // Past f32's range only with the speed put in (a launch): start afresh.
                let what = format!("{what}: {divergence}");
                watch.check(&motion_of(&simulation), &settings, &what);
                watch.out_of_range += 1;
                break;
            }
            watch.check(&motion_of(&simulation), &settings, &what);
        }
        if engine == EngineChoice::Fast && simulation.is_sound() {
            let relative = simulation
                .engine_as::<FastSimulation>()
                .expect("the fast engine")
                .relative_error();
            assert!(
                Family::builtins().all(|f| relative.get(f).is_none_or(f64::is_finite)),
                "{relative:?}"
            );
        }
    }
    watch.print(name);
}

#[test]
fn the_reference_engine_survives_random_edits_and_settings() {
    survives_random_edits_grabs_and_settings(EngineChoice::Reference, seed(13), "reference engine");
}

#[test]
fn the_fast_engine_survives_random_edits_grabs_and_settings() {
    survives_random_edits_grabs_and_settings(EngineChoice::Fast, seed(31), "fast engine");
}
