//! What every mesh target asserts of what a loader gives: an error names a line of the file
//! (or none), and a mesh is one the solver can take.

use std::path::Path;
use tetlab_core::input::limits::MAX_COORDINATE;
use tetlab_core::input::text_file::decode;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::Scene;
use tetlab_core::scene::mesh::gmsh;
use tetlab_core::scene::mesh::{MeshError, TetMesh};
use tetlab_core::simulation::{Settings, Simulation};

/// An error's line is one of the file's (or one past its end, where it ended too soon).
pub fn error(e: &MeshError, text: &str) {
    if let Some(line) = e.line {
        assert!(line >= 1 && line <= text.lines().count() + 1, "{e}");
    }
    assert!(!e.message.is_empty());
}

/// Every index in range, every coordinate finite and within the limit.
pub fn mesh(mesh: &TetMesh) {
    assert!(!mesh.tets.is_empty());
    for tet in &mesh.tets {
        for &i in tet {
            assert!((i as usize) < mesh.positions.len());
        }
    }
    for p in &mesh.positions {
        assert!(p.is_finite() && p.abs().max_element() <= MAX_COORDINATE);
    }
}

/// A loaded scene simulates one frame soundly and measures finitely (for small meshes: the
/// fuzzer's time goes to parsing).
pub fn scene(scene: Scene) {
    if scene.mesh.tets.len() > 64 {
        return;
    }
    let mut simulation = Simulation::new(&scene, Settings::default());
    Metrics::measure_sound(&simulation).expect("a loaded mesh is sound at rest");
    simulation.step();
    let metrics = Metrics::measure(&simulation);
    assert!(metrics.headline().iter().all(|(_, v)| !v.is_nan()));
    assert!(metrics.residual.every_place().all(|v| !v.is_nan()));
}

/// A Gmsh file of version `format` (its `$MeshFormat` line) whose sections are `data`.
#[allow(dead_code)] // the TetGen target does not use it
pub fn gmsh(format: &str, data: &[u8]) {
    let Ok(body) = decode(data) else {
        return;
    };
    let text = format!("$MeshFormat\n{format}\n$EndMeshFormat\n{body}");
    match gmsh::parse(Path::new("fuzz.msh"), &text) {
        Ok((mesh, report)) => {
            self::mesh(&mesh);
            scene(Scene::from_mesh("fuzz".into(), mesh, report));
        }
        Err(e) => error(&e, &text),
    }
}
