//! Each body of a scene file made of its own stuff: its density, its own material (for the
//! families a material gives: the neo-Hookean pair) and the built-in families laid on it. A body
//! of its own material moves as it would alone under that material set for the whole scene, on
//! both engines; density and stiffness scaled together leave a body's motion as it was, to the
//! bit (the projections see only their ratio); the energy account books each constraint with its
//! own compliance; and every mistake is named at file:line:column.

use glam::DVec3;
use std::path::Path;
use tetlab_core::constraints::material::Material;
use tetlab_core::constraints::{Families, Family};
use tetlab_core::measures::energy_account::{Energy, EnergyWatch};
use tetlab_core::scene::Scene;
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

fn scene(text: &str) -> Scene {
    Scene::parse_file(Path::new("bodies.toml"), text).unwrap_or_else(|e| panic!("{e}"))
}

/// The neo-Hookean pair alone, on `engine`, with `material` for the bodies of none of their own.
fn settings(engine: EngineChoice, material: Material) -> Settings {
    let mut settings = Settings {
        engine,
        material,
        ..Settings::default()
    };
    settings.active = Families::builtin().parse_list("neohookean").unwrap();
    settings
}

fn soft() -> Material {
    Material::parse("E=1e5,nu=0.3").unwrap()
}

/// The particles `range` of `simulation`, as they are now.
fn part(simulation: &Simulation, range: std::ops::Range<u32>) -> Vec<DVec3> {
    simulation.positions()[range.start as usize..range.end as usize].to_vec()
}

fn run(simulation: &mut Simulation, frames: usize) {
    for _ in 0..frames {
        simulation.step();
    }
}

/// A stiff cube beside a soft one (`material` of its own), apart; and the soft one alone.
const SIDE_BY_SIDE: &str = "[[body]]\nname = \"stiff\"\nmesh = \"cube\"\nresolution = 2\n\
     [[body]]\nname = \"soft\"\nmesh = \"cube\"\nresolution = 2\ntranslate = [2, 0, 0]\n\
     material = \"E=1e5,nu=0.3\"\n";
const ALONE: &str = "[[body]]\nmesh = \"cube\"\nresolution = 2\ntranslate = [2, 0, 0]\n";

#[test]
fn a_body_of_its_own_material_moves_as_it_would_alone_under_that_material() {
    let frames = 30;
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let two = scene(SIDE_BY_SIDE);
        let mut both = Simulation::new(&two, settings(engine, Material::default()));
        let mut alone = Simulation::new(&scene(ALONE), settings(engine, soft()));
        run(&mut both, frames);
        run(&mut alone, frames);
        let (stiff, soft_body) = (
            two.bodies[0].particles.clone(),
            two.bodies[1].particles.clone(),
        );
        let (mine, its) = (part(&both, soft_body), part(&alone, 0..27));
        let apart = (mine.iter().zip(&its))
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max);
        eprintln!("{engine:?}: the soft cube is {apart:.2e} m from itself alone");
        match engine {
            // Its constraints touch only its particles, each with the arithmetic it has alone.
            EngineChoice::Reference => assert_eq!(mine, its, "the soft cube, not bit for bit"),
            // The fast engine colours the two bodies together, so the order within a sweep
            // differs from the cube's alone: f32 rounding apart (its unit roundoff is 6e-8 m at
            // 1 m; 1e-5 m leaves it room to grow over the 30 frames' 3,000 substeps).
            _ => assert!(apart < 1e-5, "{engine:?}: {apart} m"),
        }
        // The soft cube, ten times as compliant, has sunk further under its weight.
        let top = |x: &[DVec3]| x.iter().fold(f64::MIN, |h, p| h.max(p.y));
        let (stiff_top, soft_top) = (top(&part(&both, stiff)), top(&mine));
        eprintln!("{engine:?}: tops at {stiff_top:.5} m (stiff) and {soft_top:.5} m (soft)");
        assert!(soft_top < stiff_top - 0.01, "{soft_top} {stiff_top}");
    }
}

#[test]
fn density_and_stiffness_scaled_together_leave_the_motion_as_it_was() {
    // Twice the density halves every inverse mass, twice E halves every compliance: each
    // projection's Δx = w ∇C Δλ is what it was, and so is the prediction x + h v + h² g.
    let plain = "[[body]]\nmesh = \"cube\"\nresolution = 2\nrotate = [10, 20, 0]\n";
    let heavy = format!("{plain}density = 2000\nmaterial = \"E=2e6,nu=0.3\"\n");
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let mut one = Simulation::new(&scene(plain), settings(engine, Material::default()));
        let mut other = Simulation::new(&scene(&heavy), settings(engine, Material::default()));
        assert_eq!(
            (one.body().lumped_inverse_masses.iter())
                .map(|w| w / 2.0)
                .collect::<Vec<_>>(),
            other.body().lumped_inverse_masses,
            "twice the density, half the inverse masses"
        );
        run(&mut one, 20);
        run(&mut other, 20);
        assert_eq!(one.positions(), other.positions(), "{engine:?}");
        // The energy doubles with the masses and stiffnesses: to rounding, since the pair's
        // store is a difference of sums.
        let (e1, e2) = (Energy::measure(&one), Energy::measure(&other));
        let elastic = |e: &Energy| e.elastic_total(one.families());
        assert!(elastic(&e1) > 0.0, "{e1:?}");
        assert!((elastic(&e2) - 2.0 * elastic(&e1)).abs() <= 1e-9 * elastic(&e1));
        assert!((e2.total - 2.0 * e1.total).abs() <= 1e-9 * e1.total.abs());
    }
}

#[test]
fn each_constraint_is_booked_with_its_own_compliance() {
    let two = scene(SIDE_BY_SIDE);
    let mut both = Simulation::new(&two, settings(EngineChoice::Reference, Material::default()));
    let mut alone = Simulation::new(&scene(ALONE), settings(EngineChoice::Reference, soft()));
    let mut watch = EnergyWatch::start(&both);
    for frame in 1..=30 {
        both.step();
        alone.step();
        watch.observe(&both, frame);
    }
    assert!(watch.gain.is_none(), "{:?}", watch.lines());
    // The soft cube's share of the scene's energy is its energy alone.
    let bodies = Energy::measure_bodies(&both);
    let (mine, its) = (&bodies[1].1, Energy::measure(&alone));
    let elastic = |e: &Energy| e.elastic_total(both.families());
    eprintln!(
        "soft cube: elastic {:.6e} J in the scene, {:.6e} J alone",
        elastic(mine),
        elastic(&its)
    );
    assert!(elastic(&its) > 0.0);
    assert!((elastic(mine) - elastic(&its)).abs() <= 1e-9 * elastic(&its));
    assert!((mine.total - its.total).abs() <= 1e-9 * its.total.abs());
    // And the bodies add up to the scene.
    let sum: f64 = bodies.iter().map(|(_, e)| e.total).sum();
    let whole = Energy::measure(&both).total;
    assert!((sum - whole).abs() <= 1e-12 * whole.abs(), "{sum} {whole}");
}

/// Three bodies: a cube of edges alone, a cube of volumes and the neo-Hookean pair, and a tet
/// of every family (it lists none).
fn three_bodies(lists: bool) -> Scene {
    let listed = |families: &str| {
        if lists {
            format!("constraints = \"{families}\"\n")
        } else {
            String::new()
        }
    };
    scene(&format!(
        "[[body]]\nmesh = \"cube\"\nresolution = 2\n{}\
         [[body]]\nmesh = \"cube\"\nresolution = 2\ntranslate = [2, 0, 0]\n{}\
         [[body]]\nmesh = \"tet\"\ntranslate = [4, 0, 0]\n",
        listed("edges"),
        listed("volume, neohookean")
    ))
}

#[test]
fn each_body_takes_the_families_it_lists() {
    let scene = three_bodies(true);
    let all = Families::builtin().parse_list("edges,volume,neohookean");
    let settings = Settings {
        active: all.unwrap(),
        ..Settings::default()
    };
    let simulation = Simulation::new(&scene, settings);
    let owners = |family: Family| -> Vec<usize> {
        let set = simulation.constraints(family);
        let mut bodies: Vec<usize> = (0..set.len())
            .map(|c| {
                let first = set.particles(c)[0];
                (scene.bodies.iter())
                    .position(|b| b.particles.contains(&first))
                    .unwrap()
            })
            .collect();
        bodies.dedup();
        bodies
    };
    // As many as the cube alone has, and the tet's 6 edges and 1 tet.
    let cube = Scene::builtin(tetlab_core::scene::Builtin::Cube, 2).unwrap();
    let (cube_edges, cube_tets) = (cube.mesh.edges().len(), cube.mesh.tets.len());
    assert_eq!(simulation.constraints(Family::EDGES).len(), cube_edges + 6);
    assert_eq!(owners(Family::EDGES), [0, 2]);
    assert_eq!(simulation.constraints(Family::VOLUME).len(), cube_tets + 1);
    assert_eq!(owners(Family::VOLUME), [1, 2]);
    assert_eq!(owners(Family::NEOHOOKEAN_DEVIATORIC), [1, 2]);
    assert_eq!(owners(Family::NEOHOOKEAN_HYDROSTATIC), [1, 2]);
}

#[test]
fn both_engines_project_only_what_each_body_takes() {
    // Compliant edges and volumes, so that the bodies sag smoothly under their weight: the
    // engines then part by f32's rounding alone, and which families a body takes shows far
    // above it.
    let all = Families::builtin().parse_list("edges,volume,neohookean");
    let mut settings = Settings {
        active: all.unwrap(),
        ..Settings::default()
    };
    settings.compliance[Family::EDGES] = 1e-4;
    settings.compliance[Family::VOLUME] = 1e-4;
    let after = |lists: bool, engine: EngineChoice| {
        let mut simulation = Simulation::new(&three_bodies(lists), Settings { engine, ..settings });
        run(&mut simulation, 10);
        simulation.positions().to_vec()
    };
    let apart = |a: &[DVec3], b: &[DVec3]| {
        (a.iter().zip(b))
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max)
    };
    let listed = after(true, EngineChoice::Reference);
    let engines = apart(&listed, &after(true, EngineChoice::Fast));
    let lists = apart(&listed, &after(false, EngineChoice::Reference));
    eprintln!("the engines are {engines:.2e} m apart; the lists move the bodies {lists:.2e} m");
    // f32's unit roundoff is 6e-8 m at 1 m: 1e-5 m leaves it room over 1,000 substeps.
    assert!(engines < 1e-5, "{engines} m");
    assert!(lists > 1e-2, "{lists} m");
}

#[test]
fn a_mistake_in_what_a_body_is_made_of_is_named_where_it_is() {
    let cases = [
        ("density = 0", "bodies.toml:3:11: density 0 is out of range"),
        (
            "density = nan",
            "bodies.toml:3:11: density NaN is not a number",
        ),
        (
            "material = \"E=1e6\"",
            "bodies.toml:3:12: material: nu is missing",
        ),
        (
            "material = \"E=1e6,nu=0.5\"",
            "bodies.toml:3:12: material: nu 0.5",
        ),
        (
            "constraints = \"edgy\"",
            "bodies.toml:3:15: constraints: 'edgy' is not a constraint family",
        ),
        (
            "constraints = \"edges,contact\"",
            "bodies.toml:3:15: constraints: contact is found between bodies",
        ),
        ("density = \"heavy\"", "bodies.toml:3:11: invalid type"),
    ];
    for (line, expected) in cases {
        let text = format!("[[body]]\nmesh = \"tet\"\n{line}\n");
        let error = Scene::parse_file(Path::new("bodies.toml"), &text).unwrap_err();
        let message = error.to_string();
        assert!(message.starts_with(expected), "{line}: {message}");
    }
}

#[test]
fn the_stability_warning_weighs_each_bodys_own_material() {
    // A cube of E = 100 GPa carries pressure waves at 1.2e4 m/s: a 0.5 m edge needs a substep
    // under 43 µs, some 390 of a 1/60 s frame.
    let text = format!(
        "{SIDE_BY_SIDE}[[body]]\nname = \"steel\"\nmesh = \"cube\"\nresolution = 2\ntranslate = [4, 0, 0]\nmaterial = \"E=1e11,nu=0.3\"\n"
    );
    let simulation = Simulation::new(
        &scene(&text),
        settings(EngineChoice::Reference, Material::default()),
    );
    let warning = simulation.stability_warning().expect("a warning");
    assert!(warning.contains("on body \"steel\""), "{warning}");
    assert!(warning.contains("E=1e11,nu=0.3"), "{warning}");
    // Without it, the soft and the stiff cube are stable at the default substeps.
    let simulation = Simulation::new(
        &scene(SIDE_BY_SIDE),
        settings(EngineChoice::Reference, Material::default()),
    );
    assert_eq!(simulation.stability_warning(), None);
}

#[test]
fn a_tets_energy_is_its_bodys() {
    // The energy of one tet (the modes panel's, `tetlab modes`): with its body's material.
    use tetlab_core::energy::element::ElementEnergy;
    let two = scene(SIDE_BY_SIDE);
    let mut both = Simulation::new(&two, settings(EngineChoice::Reference, Material::default()));
    let mut alone = Simulation::new(&scene(ALONE), settings(EngineChoice::Reference, soft()));
    run(&mut both, 10);
    run(&mut alone, 10);
    let first = two.bodies[1].tets.start as usize;
    for t in 0..two.bodies[1].tets.len() {
        let (mine, x) = ElementEnergy::of_tet(&both, first + t).unwrap();
        let (its, y) = ElementEnergy::of_tet(&alone, t).unwrap();
        assert_eq!(x, y, "tet {t}: the same corners, bit for bit");
        let at = |x: [DVec3; 4]| x.map(|p| p.to_array());
        assert_eq!(mine.energy(&at(x)), its.energy(&at(y)), "tet {t}");
        assert_eq!(mine.corner_mass(), its.corner_mass(), "tet {t}");
    }
}
