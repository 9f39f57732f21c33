//! Scenes of several bodies written as files (`assets/scenes/*.toml`): each body a built-in or a
//! mesh file, placed and launched; the bodies are one mesh whose parts share no particle, each
//! measured on its own; every mistake is named at file:line:column; and a launched body flies
//! the same on both engines, and again after a reset.

use glam::DVec3;
use std::path::Path;
use tetlab_core::constraints::volume::signed_volume;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::{Scene, SceneError};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

fn thrown() -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/thrown.toml");
    Scene::from_spec(path.to_str().unwrap(), 4).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_bodies_are_placed_and_part_one_mesh() {
    let scene = thrown();
    let names: Vec<&str> = scene.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["cube", "ball", "beam"]);
    // The parts follow one another and cover the mesh; no tet reaches outside its body.
    let mut next = (0, 0);
    for body in &scene.bodies {
        assert_eq!((body.particles.start, body.tets.start), next);
        next = (body.particles.end, body.tets.end);
        for t in body.tets.clone() {
            let tet = scene.mesh.tets[t as usize];
            assert!(tet.iter().all(|i| body.particles.contains(i)), "{tet:?}");
        }
    }
    assert_eq!(
        next,
        (
            scene.mesh.positions.len() as u32,
            scene.mesh.tets.len() as u32
        )
    );
    let part = |k: usize| {
        let range = scene.bodies[k].particles.clone();
        &scene.mesh.positions[range.start as usize..range.end as usize]
    };
    let (lo, hi) = tetlab_core::scene::mesh::bounds(part(1));
    // The ball of radius 0.5 scaled by 0.8 about its centre, moved 2 along z (and resting on
    // the ground as the built-in does).
    assert!(
        ((hi - lo) - DVec3::splat(0.8)).abs().max_element() < 1e-12,
        "{lo} {hi}"
    );
    assert!((0.5 * (lo + hi) - DVec3::new(0.0, 0.5, 2.0)).length() < 1e-12);
    // The beam turned a quarter about y: its length along z now; its held end carried along.
    let (lo, hi) = tetlab_core::scene::mesh::bounds(part(2));
    assert!(((hi - lo) - DVec3::new(0.5, 0.5, 2.0)).abs().max_element() < 1e-12);
    assert_eq!(
        scene.pinned.len(),
        9,
        "the beam's end at resolution 2: 3 × 3 particles"
    );
    assert!(
        scene
            .pinned
            .iter()
            .all(|i| scene.bodies[2].particles.contains(i))
    );
    assert_eq!(scene.bodies[1].velocity, DVec3::new(0.5, 3.0, 0.0));
}

/// The error of the scene file `text`.
fn mistake(text: &str) -> String {
    match Scene::parse_file(Path::new("s.toml"), text) {
        Ok(_) => panic!("no mistake found in {text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn every_mistake_is_named_at_its_place() {
    let e = mistake("[[body]]\nmesh = \"cube\"\ncolour = \"red\"\n");
    assert!(e.starts_with("s.toml:3:1:") && e.contains("colour"), "{e}");
    let e = mistake("[[body]]\nmesh = \"cube\"\nscale = 0\n");
    assert!(e.starts_with("s.toml:3:9: scale is 0"), "{e}");
    // A scale of the wrong shape is told what a scale is, at its place.
    for (scale, shown) in [("[1, 2]", "[1, 2]"), ("\"big\"", "\"big\"")] {
        let e = mistake(&format!("[[body]]\nmesh = \"cube\"\nscale = {scale}\n"));
        assert!(
            e.starts_with(&format!("s.toml:3:9: scale is {shown}")) && e.contains("one per axis"),
            "{e}"
        );
    }
    let e = mistake("[[body]]\nmesh = \"cube\"\nvelocity = [0, nan, 0]\n");
    assert!(
        e.starts_with("s.toml:3:12: velocity") && e.contains("finite"),
        "{e}"
    );
    let e = mistake("[[body]]\nmesh = \"cube\"\ntranslate = [0, 1e7, 0]\n");
    assert!(
        e.starts_with("s.toml:3:13: translate") && e.contains("within"),
        "{e}"
    );
    for bend in ["[0, 0.1]", "[190, 0.1]", "[90, 0]", "[90, inf]"] {
        let e = mistake(&format!("[[body]]\nmesh = \"cube\"\nbend = {bend}\n"));
        assert!(
            e.starts_with("s.toml:3:8: bend is") && e.contains("[degrees, inner radius]"),
            "{e}"
        );
    }
    let e = mistake("[[body]]\nmesh = \"teapot\"\n");
    assert!(e.starts_with("s.toml:2:8:") && e.contains("teapot"), "{e}");
    let e = mistake("[[body]]\nmesh = \"cube\"\nresolution = 0\n");
    assert!(
        e.starts_with("s.toml:2:8:") && e.contains("resolution"),
        "{e}"
    );
    let e = mistake("name = \"empty\"\n");
    assert!(e.starts_with("s.toml: no body"), "{e}");
    let e = mistake(
        "[[body]]\nname = \"a\"\nmesh = \"cube\"\n[[body]]\nname = \"a\"\nmesh = \"tet\"\n",
    );
    assert!(
        e.starts_with("s.toml:5:8: two bodies are named \"a\""),
        "{e}"
    );
    let e = mistake(
        "[[body]]\nmesh = \"cube\"\nresolution = 128\n[[body]]\nmesh = \"cube\"\nresolution = 128\n",
    );
    assert!(
        e.starts_with("s.toml:5:8:") && e.contains("more than"),
        "{e}"
    );
    let e = mistake("[[body]\nmesh = \"cube\"\n");
    assert!(e.starts_with("s.toml:1:"), "{e}");
    // A mesh file's own mistake is named in that file.
    let dir = std::env::temp_dir().join(format!("tetlab-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("broken.node"), "4 3 0 0\n1 0 0 0\n").unwrap();
    let scene = dir.join("s.toml");
    std::fs::write(&scene, "[[body]]\nmesh = \"broken.node\"\n").unwrap();
    let e = Scene::load_file(&scene).unwrap_err();
    assert!(matches!(e, SceneError::Mesh(_)), "{e}");
    assert!(e.to_string().contains("broken"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_body_below_the_ground_lifts_the_scene() {
    let text = "[[body]]\nmesh = \"cube\"\nresolution = 1\ntranslate = [0, -0.25, 0]\n\
                [[body]]\nmesh = \"tet\"\ntranslate = [3, 0, 0]\n";
    let scene = Scene::parse_file(Path::new("s.toml"), text).unwrap();
    let lowest = scene
        .mesh
        .positions
        .iter()
        .map(|p| p.y)
        .fold(f64::MAX, f64::min);
    assert_eq!(lowest, 0.0);
    assert!(
        scene.notes.iter().any(|n| n.contains("lifted")),
        "{:?}",
        scene.notes
    );
    // As a whole: the tet rests 0.25 above the ground, where the cube's lift put it.
    let tet = &scene.mesh.positions[8..];
    assert_eq!(tet.iter().map(|p| p.y).fold(f64::MAX, f64::min), 0.25);
}

/// Each body's centre of mass after `frames` frames of the thrown scene on `engine`, and after
/// a reset and the same frames again.
fn flight(engine: EngineChoice, frames: usize) -> (Vec<DVec3>, Vec<DVec3>) {
    let settings = Settings {
        engine,
        ..Settings::default()
    };
    let mut simulation = Simulation::new(&thrown(), settings);
    let centres = |simulation: &mut Simulation| {
        for _ in 0..frames {
            simulation.step();
        }
        let bodies = Metrics::measure_bodies(simulation);
        bodies
            .iter()
            .map(|(_, m)| m.centre_of_mass)
            .collect::<Vec<_>>()
    };
    let first = centres(&mut simulation);
    simulation.reset();
    let again = centres(&mut simulation);
    (first, again)
}

#[test]
fn a_launched_body_flies_the_same_on_both_engines_and_after_a_reset() {
    let frames = 20;
    let (reference, again) = flight(EngineChoice::Reference, frames);
    assert_eq!(reference, again, "a reset launches the bodies again");
    let (fast, _) = flight(EngineChoice::Fast, frames);
    // The ball, thrown at (0.5, 3, 0) m/s from its centre at (0, 0.5, 2): a parabola for the
    // first 20 frames (its peak is at 0.31 s, above the ground), which both engines fly.
    let t = frames as f64 / 60.0;
    let parabola = DVec3::new(0.5 * t, 0.5 + 3.0 * t - 0.5 * 9.81 * t * t, 2.0);
    for (engine, centres) in [("reference", &reference), ("fast", &fast)] {
        let off = centres[1].distance(parabola);
        eprintln!("{engine}: the ball is {off:.1e} m from the parabola after {frames} frames");
        // Gravity enters each substep (h = 1/6000 s): the symplectic Euler's offset is g h t / 2.
        assert!(
            off < 1e-3,
            "{engine}: the ball is {off} m from the parabola"
        );
    }
    // The cube and the beam stay where they rest and hang.
    for k in [0, 2] {
        assert!(
            reference[k].distance(fast[k]) < 1e-4,
            "{k}: {} {}",
            reference[k],
            fast[k]
        );
    }
}

/// `bend` folds a body's rest shape and keeps every tet the right way round (the map's
/// Jacobian has a positive determinant); `free` lets go of the particles the built-in beam
/// holds. A beam bent by 180° is a hairpin: its far end comes back over its near one.
#[test]
fn a_bent_body_keeps_its_tets_the_right_way_round_and_free_lets_go_of_its_pins() {
    let held = Scene::parse_file(
        Path::new("held.toml"),
        "[[body]]\nmesh = \"beam\"\nresolution = 2\n",
    )
    .unwrap();
    assert!(!held.pinned.is_empty(), "the beam holds its end");
    let text = "[[body]]\nmesh = \"beam\"\nresolution = 2\nfree = true\n\
                scale = [1, 0.2, 0.5]\nbend = [180, 0.05]\n";
    let bent = Scene::parse_file(Path::new("bent.toml"), text).unwrap();
    assert!(bent.pinned.is_empty(), "free: nothing held");
    let volumes: Vec<f64> = (bent.mesh.tets.iter())
        .map(|t| signed_volume(&t.map(|i| bent.mesh.positions[i as usize])))
        .collect();
    let smallest = volumes.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(smallest > 0.0, "a tet turned over: {smallest}");
    // The lower leg stays where the beam was (its underside at y = 1.2) and the upper leg lies
    // above it, twice the inner radius above the lower leg's top (0.1 high).
    let (lo, hi) = tetlab_core::scene::mesh::bounds(&bent.mesh.positions);
    assert!((lo.y - 1.2).abs() < 1e-12, "{lo}");
    assert!((hi.y - lo.y - (0.1 + 0.1 + 0.1)).abs() < 1e-9, "{lo} {hi}");
    assert!((hi.x - lo.x) < 1.2, "folded in two: {lo} {hi}");
}

/// Every scene file of assets/scenes is built into tetlab (what a link names) and loads, as
/// its file does; those that need the reference meshes skip without ../shared/meshes.
#[test]
fn every_shipped_scene_file_loads() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes");
    let mut on_disk: Vec<String> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".toml"))
        .collect();
    on_disk.sort();
    let shipped: Vec<&str> = tetlab_core::scene::SHIPPED.iter().map(|s| s.file).collect();
    assert_eq!(shipped, on_disk);
    for file in tetlab_core::scene::SHIPPED {
        let needs_meshes = file.text.contains("shared/meshes");
        if needs_meshes && tetlab_core::input::shared_meshes::for_test(file.file).is_none() {
            continue;
        }
        let scene = file
            .scene()
            .unwrap_or_else(|e| panic!("{}: {e}", file.file));
        let from_disk = Scene::load_file(&folder.join(file.file)).unwrap();
        assert_eq!(scene.mesh, from_disk.mesh, "{}", file.file);
        assert!(
            scene.bodies.len() >= 2 || file.file == "folded-bar.toml",
            "{}",
            file.file
        );
    }
}
