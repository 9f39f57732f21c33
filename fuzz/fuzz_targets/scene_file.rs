//! A scene file. Whatever the bytes, reading gives a scene or an error naming the file and a
//! line that exists; never a panic. Bodies are built only from small built-ins (up to 500 tets
//! each; mesh files are refused), so that the fuzzer's time goes to parsing and placing. A scene
//! read is then run one frame with contact on (edges, volume and contact, 5 substeps) on the
//! reference engine: its positions stay finite, whatever the placements, scales and velocities.

#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use tetlab_core::input::text_file::decode;
use tetlab_core::scene::{Scene, SceneError};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

#[path = "../support/small_scenes.rs"]
mod small_scenes;

use small_scenes::small;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = decode(data) else {
        return;
    };
    match Scene::parse_file_with(Path::new("fuzz.toml"), text, &small) {
        Ok(scene) => {
            assert!(!scene.bodies.is_empty());
            assert!(scene.mesh.positions.iter().all(|p| p.is_finite()));
            if scene.mesh.tets.len() > 2000 {
                return;
            }
            let mut simulation = Simulation::new(&scene, Settings::default());
            let active = simulation
                .families()
                .parse_list("edges,volume,contact")
                .unwrap();
            simulation.set_settings(Settings {
                active,
                engine: EngineChoice::Reference,
                substeps: 5,
                ..Settings::default()
            });
            simulation.step();
            assert!(simulation.positions().iter().all(|p| p.is_finite()));
        }
        Err(e) => {
            let message = e.to_string();
            assert!(message.starts_with("fuzz.toml"), "{message}");
            if let SceneError::File {
                at: Some((line, _)),
                ..
            } = e
            {
                assert!(line >= 1 && line <= text.lines().count() + 1, "{message}");
            }
        }
    }
});
