//! Masses lumped from the rest shape: each tet's mass, density × |V₀|, shared equally by its four
//! corners; each body of a scene file has its own density ([`crate::scene::SceneBody::density`]).

use crate::constraints::volume::signed_volume;
use crate::scene::SceneBody;
use crate::scene::mesh::TetMesh;

/// Density used to lump masses: 1000 kg/m³.
pub const DENSITY: f64 = 1000.0;

/// 1 / Σ (ρ × |V₀| / 4) over the tets at each particle, ρ the density of the body the tet
/// belongs to among `bodies` ([`DENSITY`] for a tet of none). A particle whose tets all have
/// zero rest volume gets the mean mass, so it still moves.
pub(crate) fn lumped_inverse_masses(mesh: &TetMesh, bodies: &[SceneBody]) -> Vec<f64> {
    let mut masses = vec![0.0; mesh.positions.len()];
    for t in 0..mesh.tets.len() {
        let v = signed_volume(&mesh.corners(t));
        let density =
            SceneBody::owner(bodies, mesh.tets[t][0]).map_or(DENSITY, |b| bodies[b].density);
        for &i in &mesh.tets[t] {
            masses[i as usize] += density * v.abs() / 4.0;
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
