//! What a frame is measured by. The CLI prints these, the recorder logs them and the GUI plots
//! them: all from [`Metrics::measure`].

use crate::constraints::{Evaluation, distance, plane, volume};
use crate::solver::{ConstraintSet, PerFamily, Simulation};
use glam::DVec3;

/// Rest volumes at or below this fraction of the mean rest volume are left out of
/// [`Metrics::min_volume_ratio`]: V/V₀ of a tet that had no volume means nothing.
pub const SLIVER: f64 = 1e-9;

/// Measurements of one state of a simulation. All values are finite.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Metrics {
    /// Tets whose signed volume is negative.
    pub inverted_tets: usize,
    /// min over tets of V / V₀ (tets with V₀ above [`SLIVER`] of the mean); 1 at rest.
    pub min_volume_ratio: f64,
    /// |ΣV − ΣV₀| / ΣV₀, the relative change of the total volume.
    pub volume_error: f64,
    /// max over edges of |l − l₀| / l₀.
    pub max_edge_strain: f64,
    /// Root mean square of C over each family's constraints (metres for edges and heights,
    /// cubic metres for volumes), whether or not the family is active.
    pub residual: PerFamily<f64>,
}

impl Metrics {
    /// The four headline measurements, by the names used in JSON, recordings and plots.
    pub fn headline(&self) -> [(&'static str, f64); 4] {
        [
            ("inverted_tets", self.inverted_tets as f64),
            ("volume_error", self.volume_error),
            ("max_edge_strain", self.max_edge_strain),
            ("min_volume_ratio", self.min_volume_ratio),
        ]
    }

    /// Measures the current state of `simulation`.
    pub fn measure(simulation: &Simulation) -> Metrics {
        let positions = simulation.positions();
        let rest_volumes = &simulation.volumes.rest;
        let total_rest: f64 = rest_volumes.iter().sum();
        let mean_rest = total_rest / rest_volumes.len().max(1) as f64;
        let mut inverted_tets = 0;
        let mut min_volume_ratio = f64::INFINITY;
        let mut total = 0.0;
        for (tet, &rest) in simulation.tets().iter().zip(rest_volumes) {
            let v = volume::signed_volume(&tet.map(|i| positions[i as usize]));
            total += v;
            if v < 0.0 {
                inverted_tets += 1;
            }
            if rest > SLIVER * mean_rest {
                min_volume_ratio = min_volume_ratio.min(v / rest);
            }
        }
        let mut max_edge_strain: f64 = 0.0;
        for (edge, &rest) in simulation
            .edges
            .particles
            .iter()
            .zip(&simulation.edges.rest)
        {
            if rest > 0.0 {
                let length = positions[edge[0] as usize].distance(positions[edge[1] as usize]);
                max_edge_strain = max_edge_strain.max((length - rest).abs() / rest);
            }
        }
        Metrics {
            inverted_tets,
            min_volume_ratio: finite_or(min_volume_ratio, 1.0),
            volume_error: if total_rest > 0.0 {
                finite_or((total - total_rest).abs() / total_rest, 0.0)
            } else {
                0.0
            },
            max_edge_strain: finite_or(max_edge_strain, 0.0),
            residual: PerFamily {
                edges: rms(&simulation.edges, positions, distance::evaluate),
                plane: rms(&simulation.planes, positions, plane::evaluate),
                volume: rms(&simulation.volumes, positions, volume::evaluate),
            },
        }
    }
}

fn rms<const N: usize>(
    set: &ConstraintSet<N>,
    positions: &[DVec3],
    evaluate: fn(&[DVec3; N], f64) -> Evaluation<DVec3, N>,
) -> f64 {
    if set.is_empty() {
        return 0.0;
    }
    let sum: f64 = set
        .particles
        .iter()
        .zip(&set.rest)
        .map(|(idx, &rest)| {
            evaluate(&idx.map(|i| positions[i as usize]), rest)
                .value
                .powi(2)
        })
        .sum();
    finite_or((sum / set.len() as f64).sqrt(), f64::MAX)
}

fn finite_or(x: f64, fallback: f64) -> f64 {
    if x.is_finite() { x } else { fallback }
}
