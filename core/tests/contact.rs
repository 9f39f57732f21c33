//! Contact between bodies (the `contact` family, `tetlab_core::simulation::contact`), on both
//! engines: a stack rests (also a soft body on a stiff one, each of its own material and
//! families), a body dropped fast does not pass through another, contact gives no
//! body energy (nor throws off one set down inside the thickness), and friction holds a block on a slope steeper than μ allows and lets it slide
//! down one that is not, as Coulomb's law says (tan θ = μ). docs/experiments.md has these as
//! k of N orderings.

#[path = "support/example_files.rs"]
mod example_files;

use example_files::example;
use glam::DVec3;
use std::path::Path;
use tetlab_core::constraints::Families;
use tetlab_core::measures::energy_account::EnergyWatch;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::Scene;
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

const ENGINES: [EngineChoice; 2] = [EngineChoice::Reference, EngineChoice::Fast];

fn asset(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/scenes")
        .join(name);
    Scene::from_spec(path.to_str().unwrap(), 4).unwrap_or_else(|e| panic!("{e}"))
}

fn text(name: &str, text: &str) -> Scene {
    Scene::parse_file(Path::new(name), text).unwrap_or_else(|e| panic!("{e}"))
}

/// `families` (with `contact` among them) on `engine`.
fn simulation(scene: &Scene, families: &str, engine: EngineChoice) -> Simulation {
    let mut table = Families::builtin();
    table.define(example("contact.toml")).unwrap();
    let mut simulation = Simulation::with_families(scene, Settings::default(), table);
    let active = simulation.families().parse_list(families).unwrap();
    simulation.set_settings(Settings {
        active,
        engine,
        ..Settings::default()
    });
    simulation
}

/// The lowest y of body `b`'s particles.
fn lowest(simulation: &Simulation, b: usize) -> f64 {
    let range = simulation.bodies()[b].particles.clone();
    let positions = &simulation.positions()[range.start as usize..range.end as usize];
    positions.iter().map(|p| p.y).fold(f64::INFINITY, f64::min)
}

/// That a body resting on another touches it (`contacts` of its particles at the end) and never
/// came closer than a tenth of the thickness (`deepest`, the deepest penetration of the run).
fn rests_on_it(engine: EngineChoice, (deepest, thickness): (f64, f64), contacts: usize) {
    assert!(
        deepest < 0.1 * thickness,
        "{engine:?}: penetration {deepest} m"
    );
    assert!(contacts > 0, "{engine:?}: it touches what it rests on");
}

/// The half-size cube on the unit cube, one thickness above it, rests for 10 s on both
/// engines: its centre moves less than a micrometre... and no contact is ever closer than a
/// tenth of the thickness.
#[test]
fn a_stack_rests() {
    let scene = asset("stacked-cubes.toml");
    for engine in ENGINES {
        let mut simulation = simulation(&scene, "edges,volume,contact", engine);
        let start = Metrics::measure_bodies(&simulation)[1].1.centre_of_mass;
        let thickness = simulation.settings().contact.thickness;
        let mut deepest: f64 = 0.0;
        for _ in 0..600 {
            simulation.step();
            deepest = deepest.max(Metrics::measure_sound(&simulation).unwrap().max_penetration);
        }
        let metrics = Metrics::measure_bodies(&simulation);
        let drift = metrics[1].1.centre_of_mass.distance(start);
        println!("{engine:?}: the upper cube drifted {drift:.3e} m; deepest {deepest:.3e} m");
        assert!(
            drift < 1e-4,
            "{engine:?}: the stack drifted {drift} m in 10 s"
        );
        rests_on_it(engine, (deepest, thickness), metrics[1].1.contacts);
    }
}

/// A soft cube of its own material and families (the neo-Hookean pair, E = 0.1 MPa, ρ = 500
/// kg/m³) on a block of rigid edges and volumes (`assets/scenes/soft-on-stiff.toml`) rests on it
/// for 3 s on both engines. It sags under its weight: undamped, it swings about the column's
/// static sag ρ g L² / 2E (8.8 mm for L = 0.6 m), and its top's mean drop over the last second
/// is within a factor 2 of that (the mesh is coarse, and the column's feet are held by
/// friction), while the block's top moves less than a hundredth of that. It stays on the block (no
/// contact closer than a tenth of the thickness; touching at the end), and the energy account
/// never grows.
#[test]
fn a_soft_body_rests_on_a_stiff_one() {
    let scene = asset("soft-on-stiff.toml");
    for engine in ENGINES {
        let mut simulation = simulation(&scene, "edges,volume,neohookean,contact", engine);
        let thickness = simulation.settings().contact.thickness;
        let top = |simulation: &Simulation, b: usize| {
            let range = simulation.bodies()[b].particles.clone();
            let positions = &simulation.positions()[range.start as usize..range.end as usize];
            positions.iter().map(|p| p.y).fold(f64::MIN, f64::max)
        };
        let start = (top(&simulation, 0), top(&simulation, 1));
        let mut watch = EnergyWatch::start(&simulation);
        let (mut deepest, mut block, mut sag): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for frame in 1..=180 {
            simulation.step();
            watch.observe(&simulation, frame);
            deepest = deepest.max(Metrics::measure_sound(&simulation).unwrap().max_penetration);
            block = block.max((start.0 - top(&simulation, 0)).abs());
            if frame > 120 {
                sag += (start.1 - top(&simulation, 1)) / 60.0;
            }
        }
        let metrics = Metrics::measure_bodies(&simulation);
        let (density, young, side, g) = (500.0, 1e5, 0.6, simulation.settings().gravity);
        let column = density * g * side * side / (2.0 * young);
        println!(
            "{engine:?}: the soft cube's top came down {sag:.4} m on average (the column's \
             {column:.4} m), the block's at most {block:.2e} m; deepest {deepest:.3e} m; {}",
            watch.lines().join("; ")
        );
        assert!(
            sag > 0.5 * column && sag < 2.0 * column,
            "{engine:?}: the soft cube sagged {sag} m"
        );
        assert!(
            block < 0.01 * column,
            "{engine:?}: the block's top moved {block} m"
        );
        rests_on_it(engine, (deepest, thickness), metrics[1].1.contacts);
        assert!(
            lowest(&simulation, 1) > start.0,
            "{engine:?}: it stays above the block"
        );
        assert!(watch.gain.is_none(), "{engine:?}: {:?}", watch.lines());
    }
}

/// A cube thrown down at 8 m/s from 0.75 m above another lands on it and bounces off it: no
/// particle of it goes below the lower cube's top by more than the thickness, on either
/// engine, in any frame of the landing and the bounce (a frame moves it 0.13 m, 13
/// thicknesses). It bounces as it would off the ground (its rigid constraints, undone within a
/// substep, give back what the landing squeezed into them: it leaves at 4.4 m/s here and at
/// 3.7 m/s off the ground).
#[test]
fn a_body_dropped_fast_does_not_pass_through() {
    let scene = text(
        "drop.toml",
        "[[body]]\nname = \"lower\"\nmesh = \"cube\"\nresolution = 3\n\
         [[body]]\nname = \"upper\"\nmesh = \"cube\"\nresolution = 2\nscale = 0.5\n\
         translate = [0.1, 1.5, 0.05]\nvelocity = [0, -8, 0]\n",
    );
    for engine in ENGINES {
        let mut simulation = simulation(&scene, "edges,volume,contact", engine);
        let thickness = simulation.settings().contact.thickness;
        let mut low = f64::INFINITY;
        for _ in 0..20 {
            simulation.step();
            low = low.min(lowest(&simulation, 1));
        }
        println!("{engine:?}: the upper cube's lowest point came to y = {low:.4}");
        assert!(low > 1.0 - thickness, "{engine:?}: it reached y = {low}");
    }
}

/// The folded bar (`assets/scenes/folded-bar.toml`): a hairpin of soft rubber (E = 0.1 MPa)
/// whose upper leg sags under its weight onto its lower one, on both engines. With contact the
/// upper leg comes to rest on the lower: it touches at the end, and no contact is ever closer
/// than a tenth of the thickness over 3 s. Without it the upper leg sinks through the lower
/// one, which is what the check would see if self-contact were missed.
#[test]
fn a_bar_folded_onto_itself_rests_on_itself() {
    let scene = asset("folded-bar.toml");
    // The legs, away from the bend (the bar's last 0.2 m): below and above the gap's middle.
    let (lo, hi) = tetlab_core::scene::mesh::bounds(&scene.mesh.positions);
    let middle = 0.5 * (lo.y + hi.y);
    let leg = |p: &DVec3| p.x < hi.x - 0.2;
    let lower: Vec<usize> = (0..scene.mesh.positions.len())
        .filter(|&i| leg(&scene.mesh.positions[i]) && scene.mesh.positions[i].y < middle)
        .collect();
    let upper: Vec<usize> = (0..scene.mesh.positions.len())
        .filter(|&i| leg(&scene.mesh.positions[i]) && scene.mesh.positions[i].y > middle)
        .collect();
    // How far the upper leg's lowest point is above the lower leg's highest (negative: through).
    let gap = |simulation: &Simulation| {
        let y = |i: &usize| simulation.positions()[*i].y;
        let top = lower.iter().map(y).fold(f64::NEG_INFINITY, f64::max);
        upper.iter().map(y).fold(f64::INFINITY, f64::min) - top
    };
    for engine in ENGINES {
        for families in ["neohookean,contact", "neohookean"] {
            let mut simulation = simulation(&scene, families, engine);
            let mut settings = *simulation.settings();
            settings.material.young = 1e5;
            simulation.set_settings(settings);
            let thickness = simulation.settings().contact.thickness;
            let mut deepest: f64 = 0.0;
            for _ in 0..180 {
                simulation.step();
                deepest = deepest.max(Metrics::measure_sound(&simulation).unwrap().max_penetration);
            }
            let (gap, touching) = (gap(&simulation), Metrics::measure(&simulation).contacts);
            println!(
                "{engine:?}, {families}: gap {gap:.4} m, {touching} touching, deepest {deepest:.3e} m"
            );
            if families.contains("contact") {
                assert!(
                    deepest < 0.1 * thickness,
                    "{engine:?}: penetration {deepest} m"
                );
                assert!(touching > 0, "{engine:?}: the upper leg rests on the lower");
                assert!(
                    gap > 0.5 * thickness,
                    "{engine:?}: the legs are {gap} m apart"
                );
            } else {
                assert!(
                    gap < -thickness,
                    "{engine:?}: without contact, a gap of {gap} m"
                );
            }
        }
    }
}

/// Two neo-Hookean cubes, the upper thrown sideways onto the lower's edge: the energy account
/// (elastic energy included) never rises above its lowest by more than its tolerance on either
/// engine. Before a particle already inside the thickness at a substep's start was held where it
/// was rather than thrown out, this landing gave 762 J (5 % of the scene's energy) in one frame.
#[test]
fn contact_gives_no_body_energy() {
    let scene = asset("two-cubes.toml");
    for engine in ENGINES {
        let mut simulation = simulation(&scene, "neohookean,contact", engine);
        let mut watch = EnergyWatch::start(&simulation);
        for frame in 1..=90 {
            simulation.step();
            watch.observe(&simulation, frame);
        }
        println!("{engine:?}: {}", watch.lines().join("; "));
        assert!(watch.gain.is_none(), "{engine:?}: {:?}", watch.lines());
    }
}

/// A box set down touching a fixed plate, inside the thickness of its surface, is not thrown
/// off on either engine: it leaves the layer as an edit settles, no faster than it was moving,
/// and rests a thickness above the plate with its energy never above its start. (Moved out of
/// the layer with where they started, the box's corners gained no speed, but the box was bent,
/// and its rigid edges undid the bend at 19 m/s: it flew 12 m high.)
#[test]
fn a_body_set_down_inside_the_layer_is_not_thrown_off() {
    let scene = text(
        "set-down.toml",
        "[[body]]\nmesh = \"cube\"\nresolution = 2\nscale = [1, 0.1, 1]\nfixed = true\n\
         [[body]]\nmesh = \"cube\"\nresolution = 2\nscale = 0.2\ntranslate = [0, 0.15, 0]\n",
    );
    for engine in ENGINES {
        let mut simulation = simulation(&scene, "edges,volume,contact", engine);
        let settings = *simulation.settings();
        // As `tetlab run` and the workbench set them.
        simulation.set_settings(Settings {
            settle_edits: true,
            ..settings
        });
        let mut watch = EnergyWatch::start(&simulation);
        let start = lowest(&simulation, 1);
        let thickness = simulation.settings().contact.thickness;
        let mut highest: f64 = start;
        for frame in 1..=60 {
            simulation.step();
            watch.observe(&simulation, frame);
            highest = highest.max(lowest(&simulation, 1));
        }
        let end = lowest(&simulation, 1);
        println!("{engine:?}: the box's underside from {start} to {end}, at most {highest} m");
        assert!(
            highest < start + 1.5 * thickness,
            "{engine:?}: the box rose to {highest} m from {start} m"
        );
        assert!(watch.gain.is_none(), "{engine:?}: {:?}", watch.lines());
    }
}

/// A block on a fixed ramp at θ = 30° (tan θ = 0.577): with μ = 0.6 it stays put; with
/// μ = 0.55 and 0.3 it slides, and after 1 s it has gone ½ g (sin θ − μ cos θ) t² down the
/// slope, to 1 % of what gravity alone would slide it (½ g sin θ t², 2.45 m), on both engines.
#[test]
fn friction_holds_a_block_on_a_slope_as_coulomb_says() {
    let theta = 30f64.to_radians();
    let normal = DVec3::new(-theta.sin(), theta.cos(), 0.0);
    let thickness = Settings::default().contact.thickness;
    // The ramp: a 3 × 0.2 × 1.5 slab about (0, 1, 0), turned by θ about z; the block, 0.3 on a
    // side, turned with it and set one thickness above its top.
    let block = DVec3::new(0.0, 1.0, 0.0) + normal * (0.1 + 0.15 + thickness);
    let file = format!(
        "[[body]]\nname = \"ramp\"\nmesh = \"cube\"\nresolution = 2\nscale = [3, 0.2, 1.5]\n\
         rotate = [0, 0, 30]\ntranslate = [0, 0.5, 0]\nfixed = true\n\
         [[body]]\nname = \"block\"\nmesh = \"cube\"\nresolution = 2\nscale = 0.3\n\
         rotate = [0, 0, 30]\ntranslate = [{}, {}, {}]\n",
        block.x,
        block.y - 0.5,
        block.z
    );
    let scene = text("slope.toml", &file);
    let down = DVec3::new(-theta.cos(), -theta.sin(), 0.0);
    for engine in ENGINES {
        for mu in [0.6, 0.55, 0.3] {
            let mut simulation = simulation(&scene, "edges,volume,contact", engine);
            let mut settings = *simulation.settings();
            settings.contact.static_friction = mu;
            settings.contact.kinetic_friction = mu;
            simulation.set_settings(settings);
            let start = Metrics::measure_bodies(&simulation)[1].1.centre_of_mass;
            for _ in 0..60 {
                simulation.step();
            }
            let end = Metrics::measure_bodies(&simulation)[1].1.centre_of_mass;
            let slid = (end - start).dot(down);
            let expected = (0.5 * 9.81 * (theta.sin() - mu * theta.cos())).max(0.0);
            println!("{engine:?}, μ = {mu}: slid {slid:.4} m, Coulomb {expected:.4} m");
            if mu > theta.tan() {
                assert!(slid.abs() < 1e-3, "{engine:?}, μ = {mu}: it slid {slid} m");
            } else {
                let gravity_alone = 0.5 * 9.81 * theta.sin();
                assert!(
                    (slid - expected).abs() < 0.01 * gravity_alone,
                    "{engine:?}, μ = {mu}: it slid {slid} m, Coulomb says {expected} m"
                );
            }
        }
    }
}

/// Contact written as a file (`assets/constraints/contact.toml`, the height formula with p0
/// and p1 swapped, its gradient by AD) lands, bounces and rests as the built-in does: the
/// thrown cube's path and the stack's rest agree to 10⁻⁹ m on the reference engine and 10⁻⁴ m
/// on the fast one (f32 rounds AD's and the formula's sums differently).
#[test]
fn contact_as_a_file_is_the_built_in() {
    let scenes = [
        asset("stacked-cubes.toml"),
        text(
            "drop.toml",
            "[[body]]\nmesh = \"cube\"\nresolution = 3\n\
             [[body]]\nmesh = \"cube\"\nresolution = 2\nscale = 0.5\n\
             translate = [0.1, 1.5, 0.05]\nvelocity = [0, -8, 0]\n",
        ),
    ];
    for scene in &scenes {
        for (engine, tolerance) in [(EngineChoice::Reference, 1e-9), (EngineChoice::Fast, 1e-4)] {
            let mut builtin = simulation(scene, "edges,volume,contact", engine);
            let mut file = simulation(scene, "edges,volume,my-contact", engine);
            let mut largest: f64 = 0.0;
            for _ in 0..30 {
                builtin.step();
                file.step();
                let apart = (builtin.positions().iter().zip(file.positions()))
                    .map(|(a, b)| a.distance(*b))
                    .fold(0.0, f64::max);
                largest = largest.max(apart);
            }
            println!("{engine:?}: the file and the built-in {largest:.2e} m apart at most");
            assert!(largest < tolerance, "{engine:?}: {largest} m apart");
        }
    }
}
