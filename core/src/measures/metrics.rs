//! What a frame is measured by. The CLI prints these, the recorder logs them and the GUI plots
//! them: all from [`Metrics::measure`]. No value is replaced by a fallback: a metric that
//! overflows is reported as it is, and [`Metrics::check`] turns it into a [`Divergence`], so that
//! nothing that is not a number is ever printed, plotted or recorded.

use crate::constraints::volume::signed_volume;
use crate::constraints::{Constraint, Families, Family, PerFamily, SubstepStart, Visit};
use crate::simulation::divergence::{Cause, Divergence};
use crate::simulation::{ConstraintSet, Simulation};
use glam::DVec3;
use std::ops::Range;

/// Rest volumes at or below this fraction of the mean rest volume are left out of
/// [`Metrics::min_volume_ratio`]: V/V₀ of a tet that had no volume means nothing.
pub const SLIVER: f64 = 1e-9;

/// Measurements of one state of a simulation. Finite for a sound state, except where
/// [`Metrics::check`] says otherwise.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Metrics {
    /// Tets whose signed volume is negative.
    pub inverted_tets: usize,
    /// min over tets of V / V₀ (tets with a positive V₀ above [`SLIVER`] of the mean |V₀|); 1 at
    /// rest, and 1 when no tet has a rest volume.
    pub min_volume_ratio: f64,
    /// |ΣV − ΣV₀| / ΣV₀, the relative change of the total volume (0 when ΣV₀ is 0).
    pub volume_error: f64,
    /// max over edges of |l − l₀| / l₀.
    pub max_edge_strain: f64,
    /// max over particles of |x − x_rest|, in metres: how far the body moved from its rest
    /// shape (a cantilever's tip deflection).
    pub max_displacement: f64,
    /// max over particles of |v|, in m/s.
    pub max_speed: f64,
    /// The centre of mass (the lumped masses' weighted mean position), in metres.
    pub centre_of_mass: DVec3,
    /// Root mean square of C over each family's constraints (metres for edges and heights,
    /// cubic metres for volumes), whether or not the family is active.
    pub residual: PerFamily<f64>,
    /// Contacts touching: the frame's contact pairs ([`crate::simulation::contact`]) whose
    /// particle is over its triangle and at most [`TOUCHING`] thicknesses above it (and, under
    /// its plane, inside the body it bounds). 0 when no family binds to contacts.
    pub contacts: usize,
    /// The largest penetration, m: over the frame's contact pairs whose particle is over its
    /// triangle, the most by which it is closer than the thickness d, max(0, d − h) with h its
    /// height above the triangle (the built-in contact's −C). A particle under the triangle's
    /// plane (h < 0) counts only where it is inside the body the triangle bounds; one that went
    /// round the rim of a part thinner than its depth is outside it.
    pub max_penetration: f64,
}

/// A contact pair touches when its particle is at most this many thicknesses above its
/// triangle ([`Metrics::contacts`]): a contact at rest holds it at one thickness, to within
/// the solver's tolerance.
pub const TOUCHING: f64 = 1.1;

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

    /// Every measurement a lesson may expect something of, by name: the headline's, then the
    /// largest speed and displacement, the contacts touching and the largest penetration.
    pub fn named(&self) -> [(&'static str, f64); 8] {
        let [a, b, c, d] = self.headline();
        [
            a,
            b,
            c,
            d,
            ("max_speed", self.max_speed),
            ("max_displacement", self.max_displacement),
            ("contacts", self.contacts as f64),
            ("max_penetration", self.max_penetration),
        ]
    }

    /// Ok when every measurement is finite; otherwise the first that is not, as the divergence
    /// of a state at `frame`.
    /// `families` names the families of the residuals.
    pub fn check(&self, families: &Families, frame: u64) -> Result<(), Divergence> {
        let more = [
            ("max_displacement", self.max_displacement),
            ("max_speed", self.max_speed),
            ("centre_of_mass", self.centre_of_mass.length()),
            ("max_penetration", self.max_penetration),
        ];
        let all = self.headline().into_iter().chain(more);
        if let Some((name, value)) = all.into_iter().find(|(_, v)| !v.is_finite()) {
            return Err(Divergence::new(frame, Cause::Metric { name, value }));
        }
        match families
            .values(&self.residual)
            .find(|(_, v)| !v.is_finite())
        {
            Some((family, value)) => {
                let family = families.name(family).to_owned();
                Err(Divergence::new(frame, Cause::Residual { family, value }))
            }
            None => Ok(()),
        }
    }

    /// The metrics of a sound state: [`Simulation::check`], then [`Metrics::measure`], then
    /// [`Metrics::check`]. What every front end calls after a frame.
    pub fn measure_sound(simulation: &Simulation) -> Result<Metrics, Divergence> {
        simulation.check()?;
        let metrics = Metrics::measure(simulation);
        metrics.check(simulation.families(), simulation.frame())?;
        Ok(metrics)
    }

    /// Measures the current state of `simulation`.
    pub fn measure(simulation: &Simulation) -> Metrics {
        let whole = 0..simulation.positions().len() as u32;
        Metrics::measure_part(simulation, whole, 0..simulation.tets().len() as u32)
    }

    /// Measures each body of a scene of several ([`Simulation::bodies`]) on its own: its name
    /// and its metrics. Empty for a scene of one body.
    pub fn measure_bodies(simulation: &Simulation) -> Vec<(String, Metrics)> {
        (simulation.bodies().iter())
            .map(|body| {
                let part = body.particles.clone();
                let metrics = Metrics::measure_part(simulation, part, body.tets.clone());
                (body.name.clone(), metrics)
            })
            .collect()
    }

    /// The metrics of the particles `particles` and the tets `tets` of `simulation`: of one
    /// body, whose elements have no particle outside it (an element is counted where its
    /// first particle is).
    fn measure_part(simulation: &Simulation, particles: Range<u32>, tets: Range<u32>) -> Metrics {
        let positions = simulation.positions();
        let range = particles.start as usize..particles.end as usize;
        let tet_range = tets.start as usize..tets.end as usize;
        let rest_volumes = || tet_range.clone().map(|t| simulation.rest_volume(t));
        let total_rest: f64 = rest_volumes().sum();
        // The scale of "a sliver": the mean size of a rest volume (a degenerate tet may be a hair
        // negative, and a mesh of them could make a signed mean negative or zero).
        let mean_rest =
            rest_volumes().map(|v| v.abs()).sum::<f64>() / tet_range.len().max(1) as f64;
        let mut inverted_tets = 0;
        let mut min_volume_ratio: Option<f64> = None;
        let mut total = 0.0;
        for (tet, rest) in simulation.tets()[tet_range.clone()]
            .iter()
            .zip(rest_volumes())
        {
            let v = signed_volume(&tet.map(|i| positions[i as usize]));
            total += v;
            if v < 0.0 {
                inverted_tets += 1;
            }
            if rest > 0.0 && rest > SLIVER * mean_rest {
                let ratio = v / rest;
                min_volume_ratio = Some(min_volume_ratio.map_or(ratio, |m| smaller(m, ratio)));
            }
        }
        let mut max_edge_strain: f64 = 0.0;
        let rest_positions = simulation.rest_positions();
        for &[a, b] in &simulation.body().edges {
            let rest = rest_positions[a as usize].distance(rest_positions[b as usize]);
            if rest > 0.0 && particles.contains(&a) {
                let length = positions[a as usize].distance(positions[b as usize]);
                max_edge_strain = larger(max_edge_strain, (length - rest).abs() / rest);
            }
        }
        let touching = contacts_of(simulation, &particles);
        Metrics {
            inverted_tets,
            min_volume_ratio: min_volume_ratio.unwrap_or(1.0),
            volume_error: if total_rest > 0.0 {
                (total - total_rest).abs() / total_rest
            } else {
                0.0
            },
            max_edge_strain,
            contacts: touching.0,
            max_penetration: touching.1,
            max_displacement: (positions[range.clone()].iter())
                .zip(&simulation.rest_positions()[range.clone()])
                .map(|(p, r)| p.distance(*r))
                .fold(0.0, larger),
            max_speed: (simulation.velocities()[range.clone()].iter())
                .map(|v| v.length())
                .fold(0.0, larger),
            centre_of_mass: simulation.centre_of_mass_of(positions, range),
            residual: simulation.families().per_family(|family| {
                simulation.families().visit(
                    family,
                    Rms {
                        set: simulation.constraints(family),
                        positions,
                        rest_positions: simulation.rest_positions(),
                        particles: particles.clone(),
                    },
                )
            }),
        }
    }
}

/// The warning a run or the workbench gives when contact let a particle under a surface: a
/// penetration `depth` deeper than the `thickness` d (the particle's height h = d − depth below
/// 0), seen at `frame`; `None` otherwise. The pairs' inequality C = h − d ≥ 0 keeps every
/// particle a thickness above the surfaces in the exact answer of the discrete problem, so a
/// particle under one is the solver's error (or one the broad phase missed): more substeps hold
/// a landing that one sweep of stiff constraints does not.
///
/// ```
/// use tetlab_core::measures::metrics::penetration_warning;
/// assert_eq!(penetration_warning(0.009, 3, 0.01), None, "inside the layer, above the surface");
/// let warning = penetration_warning(0.074, 76, 0.01).unwrap();
/// assert!(warning.contains("frame 76") && warning.contains("6.4e-2 m under"), "{warning}");
/// assert_eq!(penetration_warning(f64::NAN, 1, 0.01), None);
/// ```
pub fn penetration_warning(depth: f64, frame: u64, thickness: f64) -> Option<String> {
    (depth > thickness).then(|| {
        format!(
            "warning: contact let a particle {:.1e} m under a surface at frame {frame} \
             (penetration {depth:.3e} m, {:.1} thicknesses): the solver's error, which more \
             substeps may remove",
            depth - thickness,
            depth / thickness
        )
    })
}

/// The touching contacts among the frame's pairs whose particle is among `particles`, and the
/// largest penetration among them ([`Metrics::contacts`], [`Metrics::max_penetration`]).
///
/// A pair whose particle is under its triangle's plane counts only where the particle is inside
/// the body the triangle bounds ([`inside_the_body_of`]): a pair is found while its particle is
/// near the triangle's outer side, and within the frame the particle may go round the rim of a
/// part of the body thinner than how far it then is under the plane (a finger, an ear), and end
/// over the triangle from the far side, outside the body. The contact pass leaves such a pair
/// alone (it was deeper than the thickness at the substep's start), and so does this measure.
fn contacts_of(simulation: &Simulation, particles: &Range<u32>) -> (usize, f64) {
    let positions = simulation.positions();
    let thickness = simulation.settings().contact.thickness;
    let mut touching = 0;
    let mut deepest: f64 = 0.0;
    for pair in simulation.contact_pairs() {
        if !particles.contains(&pair[0]) {
            continue;
        }
        let Some(c) = crate::simulation::contact::over_and_closing(positions, *pair, thickness)
        else {
            continue;
        };
        let height = c + thickness;
        if height < 0.0 && !inside_the_body_of(simulation, *pair) {
            continue;
        }
        if height <= TOUCHING * thickness {
            touching += 1;
        }
        deepest = larger(deepest, -c);
    }
    (touching, deepest)
}

/// Whether the particle of `pair` ([particle, a, b, c]) lies inside a tet of the body whose
/// surface has the triangle (a, b, c), other than the tets it is a corner of (contact of a body
/// with its own surface): inside, or on a face, of a tet of non-zero volume, by the signs of
/// the four volumes it makes with the tet's faces. A body of the scene's
/// ([`Simulation::bodies`]), or the whole mesh where the scene has none.
fn inside_the_body_of(simulation: &Simulation, pair: [u32; 4]) -> bool {
    let positions = simulation.positions();
    let tets = simulation.tets();
    let bodies = simulation.bodies();
    let range = crate::scene::SceneBody::owner(bodies, pair[1]).map_or(0..tets.len(), |b| {
        bodies[b].tets.start as usize..bodies[b].tets.end as usize
    });
    let x = positions[pair[0] as usize];
    tets[range].iter().any(|tet| {
        if tet.contains(&pair[0]) {
            return false;
        }
        let p = tet.map(|i| positions[i as usize]);
        let whole = signed_volume(&p);
        if whole == 0.0 || !whole.is_finite() {
            return false;
        }
        (0..4).all(|k| {
            let mut q = p;
            q[k] = x;
            signed_volume(&q) * whole.signum() >= 0.0
        })
    })
}

/// The smaller of two numbers, NaN if either is (f64::min would drop a NaN).
fn smaller(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

/// The larger of two numbers, NaN if either is.
fn larger(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// √(mean C²) over the constraints of `set`; 0 when there are none.
struct Rms<'a> {
    set: &'a ConstraintSet,
    positions: &'a [DVec3],
    rest_positions: &'a [DVec3],
    /// Only the constraints whose first particle is among these.
    particles: Range<u32>,
}

impl Visit for Rms<'_> {
    type Output = f64;

    fn visit<const N: usize, C: Constraint<N>>(self, _: Family, constraint: &C) -> f64 {
        let set = self.set;
        if set.is_empty() {
            return 0.0;
        }
        let mine = (0..set.len()).filter(|&c| self.particles.contains(&set.particles(c)[0]));
        let count = mine.clone().count();
        if count == 0 {
            return 0.0;
        }
        let sum: f64 = mine
            .map(|c| {
                let idx: [u32; N] = std::array::from_fn(|k| set.particles(c)[k]);
                let p = idx.map(|i| self.positions[i as usize]);
                let shape = idx.map(|i| self.rest_positions[i as usize]);
                // Outside a substep: a constraint on velocities is measured at rest.
                constraint
                    .evaluate_stored(
                        &p,
                        set.rest()[c],
                        &shape,
                        set.stored(c),
                        SubstepStart::at_rest(&p),
                    )
                    .value
                    .powi(2)
            })
            .sum();
        (sum / count as f64).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Builtin, Scene};
    use crate::simulation::Settings;
    use crate::simulation::divergence::Cause;

    /// A particle under a surface triangle's plane is a penetration only inside the body the
    /// triangle bounds: a corner of a box falling with a plate 5 cm thick, a little more than the
    /// thickness above it, counts 3 cm deep when it is moved 2 cm into the plate, and not at all when it is under the plate, outside it (as a
    /// particle that went round the rim of a thin part ends), though it is still over the
    /// triangle of its pair, 12.5 cm under its plane.
    #[test]
    fn a_particle_round_the_rim_of_a_thin_part_is_no_penetration() {
        let text = "[[body]]\nmesh = \"cube\"\nresolution = 1\nscale = [1, 0.05, 1]\n\
                    translate = [0, 1, 0]\n\
                    [[body]]\nmesh = \"cube\"\nresolution = 1\nscale = 0.2\n\
                    translate = [0, 1.1355, 0]\n";
        let scene = Scene::parse_file(std::path::Path::new("t.toml"), text).unwrap();
        let mut simulation = Simulation::new(&scene, Settings::default());
        let active = (simulation.families().parse_list("edges,volume,contact")).unwrap();
        let settings = *simulation.settings();
        simulation.set_settings(Settings { active, ..settings });
        simulation.step();
        let corner = (simulation.bodies()[1].particles.clone())
            .min_by(|&a, &b| {
                let y = |i: u32| simulation.positions()[i as usize].y;
                y(a).total_cmp(&y(b))
            })
            .unwrap();
        let paired = simulation.contact_pairs().iter().filter(|p| p[0] == corner);
        assert!(
            paired.count() > 0,
            "the box's corner is paired with the plate's top"
        );
        let at = simulation.positions()[corner as usize];
        let plate = 0..8;
        let top = (plate.map(|i| simulation.positions()[i].y)).fold(f64::MIN, f64::max);
        simulation.place(corner as usize, DVec3::new(at.x, top - 0.02, at.z));
        let inside = Metrics::measure(&simulation);
        assert!((inside.max_penetration - 0.03).abs() < 1e-9, "{inside:?}");
        simulation.place(corner as usize, DVec3::new(at.x, top - 0.125, at.z));
        let outside = Metrics::measure(&simulation);
        assert!(outside.max_penetration < 1e-6, "{outside:?}");
    }

    /// Found by the fuzzer: a mesh whose tets all have (nearly) zero rest volume, two of its
    /// points coinciding, gave V / V₀ = 0 / 0 at rest.
    #[test]
    fn a_mesh_of_degenerate_tets_measures_finitely_at_rest() {
        let p = |x, y, z| DVec3::new(x, y, z);
        let positions = vec![
            p(0.0, 0.8, 0.0),
            p(0.0, 0.8, 0.0),
            p(0.5, 0.8, 0.866),
            p(0.5, 1.6, 0.289),
            p(0.5, 0.0, 0.289),
        ];
        let (mesh, report) =
            crate::scene::mesh::TetMesh::new(positions, vec![[3, 0, 1, 2], [0, 1, 2, 4]]);
        assert_eq!(report.degenerate_tets, 2);
        let scene = Scene::from_mesh("coincident".into(), mesh, report);
        let mut simulation = Simulation::new(&scene, Settings::default());
        let metrics = Metrics::measure_sound(&simulation).expect("finite at rest");
        assert_eq!(
            metrics.min_volume_ratio, 1.0,
            "no tet has a rest volume to compare"
        );
        simulation.step();
        assert!(Metrics::measure_sound(&simulation).is_ok());
    }

    #[test]
    fn a_metric_that_overflows_is_reported_not_replaced() {
        let tet = Scene::builtin(Builtin::Tet, 1).unwrap().mesh;
        let tiny: Vec<DVec3> = tet.positions.iter().map(|p| *p * 1e-100).collect();
        let (mesh, report) = crate::scene::mesh::TetMesh::new(tiny, tet.tets);
        let scene = Scene::from_mesh("tiny".into(), mesh, report);
        let mut simulation = Simulation::new(&scene, Settings::default());
        assert_eq!(Metrics::measure_sound(&simulation).map(|_| ()), Ok(()));
        // Positions still below the sound limit of 1e30, but the tet is (1e129)³ times its rest
        // volume: V / V₀ and the relative volume error overflow.
        let grown: Vec<DVec3> = simulation.positions().iter().map(|p| *p * 1e129).collect();
        simulation.set_positions(&grown);
        assert!(simulation.is_sound());
        let metrics = Metrics::measure(&simulation);
        assert_eq!(metrics.min_volume_ratio, f64::INFINITY, "{metrics:?}");
        assert_eq!(metrics.volume_error, f64::INFINITY, "{metrics:?}");
        let divergence = Metrics::measure_sound(&simulation).unwrap_err();
        assert!(
            matches!(
                divergence.cause,
                Cause::Metric {
                    name: "volume_error",
                    ..
                }
            ),
            "{divergence}"
        );
        assert!(smaller(1.0, f64::NAN).is_nan() && larger(f64::NAN, 1.0).is_nan());
    }
}
