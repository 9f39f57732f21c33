//! The cantilever of the static-bias experiment, shared by its test and its benchmark: the beam
//! scene at resolution 1 (clamped at x = 0), neo-Hookean E = 10 MPa, ν = 0.3, 4 iterations,
//! damping 10/s, hanging free (no ground: the beam lies on the ground's plane, which would hold
//! it up), at `substeps`, on the reference engine or on the one that rebuilds the positions from
//! the multipliers after every sweep ([`super::rebuilt_engine::Rebuilt`]).

use tetlab_core::constraints::PerFamily;
use tetlab_core::constraints::material::Material;
use tetlab_core::scene::{Builtin, Scene};
use tetlab_core::simulation::{Settings, Simulation};

/// The cantilever at `substeps`, at rest at its rest shape, on the reference engine or rebuilt.
pub fn cantilever(substeps: u32, rebuilt: bool) -> Simulation {
    let scene = Scene::builtin(Builtin::Beam, 1).unwrap();
    let mut settings = Settings {
        active: PerFamily::builtin_list("neohookean").unwrap(),
        substeps,
        iterations: 4,
        damping: 10.0,
        ..Settings::default()
    };
    settings.ground = false;
    settings.material = Material {
        young: 1e7,
        poisson: 0.3,
    };
    let mut simulation = Simulation::new(&scene, settings);
    if rebuilt {
        simulation.use_engine(super::rebuilt_engine::Rebuilt::build, "rebuilt");
    }
    simulation
}
