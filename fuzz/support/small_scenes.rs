//! The scene maker of the fuzz targets that read files naming scenes (lessons, scene files):
//! small built-ins only, so that the fuzzer's time goes to parsing.

use tetlab_core::input::limits::{MAX_TETS, RESOLUTION};
use tetlab_core::scene::{Builtin, Scene, SceneError};

/// Built-in scenes of up to 500 tets are built; larger valid ones are refused here (not built,
/// to keep each run fast); out-of-range ones go to `Scene::builtin`, which refuses them before
/// allocating anything. Anything else, a mesh file included, is refused: a fuzzed path could
/// name any file on the machine.
pub fn small(name: &str, resolution: u32) -> Result<Scene, SceneError> {
    let Some(builtin) = Builtin::from_name(name) else {
        return Err(SceneError::Unknown(name.to_owned()));
    };
    let valid = RESOLUTION.contains(resolution) && builtin.tets(resolution) <= MAX_TETS as u64;
    if valid && builtin.tets(resolution) > 500 {
        return Err(SceneError::Resolution("not built while fuzzing".into()));
    }
    Scene::builtin(builtin, resolution)
}
