//! What to draw, derived from a simulation once for every front end: the recorder logs it and
//! the GUI paints it, so both show the same arrows in the same colours: the surface
//! (`surface`), the arrows (`arrows`), and here the colours and the length scales they share.

mod arrows;
mod surface;

pub use arrows::{
    Arrow, ArrowSelection, CORRECTION, DISAGREEMENT, GRADIENT_ARROW_LENGTH, MODE, Quantity,
    along_mode, mode_arrows, projection_arrows, selected_arrows,
};
pub use surface::{
    ALL_FACES_UP_TO, contact_arrows, display_edges, display_faces, edge_strips, faces_with_tets,
    held_particle_colours, inverted_tets, particle_colours, selected_contact_arrows,
};

use crate::constraints::volume::signed_volume;
use crate::constraints::{Families, Family};
use crate::scene::mesh::{TET_EDGES, TetMesh, bounds};
use crate::simulation::{Projection, Simulation};
use glam::DVec3;

/// An sRGB colour with alpha, 0–255 per channel.
pub type Rgba = [u8; 4];

/// Tets and particles in good shape.
pub const HEALTHY: Rgba = [150, 180, 210, 255];
/// Inverted tets (signed volume < 0) and their particles.
pub const INVERTED: Rgba = [220, 40, 40, 255];
/// Edges.
pub const EDGE: Rgba = [60, 60, 70, 255];

/// The colour of a constraint family's arrows ([`crate::constraints::Row::colour`]): edges
/// orange, heights green, volume blue.
pub fn family_colour(families: &Families, family: Family) -> Rgba {
    families.row(family).colour
}

/// The colour map of V/V₀: red at ≤ 0 (flat or inverted), through yellow at ½, to white at ≥ 1.
pub fn volume_ratio_colour(ratio: f64) -> Rgba {
    let t = if ratio.is_finite() {
        ratio.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (r, g, b) = if t < 0.5 {
        (1.0, 2.0 * t, 0.0)
    } else {
        (1.0, 1.0, 2.0 * (t - 0.5))
    };
    [(r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8, 255]
}

/// The diagonal of [`bounds`]: the natural length scale for drawing a body (at least 10⁻⁶).
pub fn body_size(positions: &[DVec3]) -> f64 {
    let (lo, hi) = bounds(positions);
    (hi - lo).length().max(1e-6)
}

/// The mean edge length of tet `tet`: the natural length scale for drawing on it.
pub(crate) fn tet_size(positions: &[DVec3], tet: &[u32; 4]) -> f64 {
    TET_EDGES
        .iter()
        .map(|&(a, b)| positions[tet[a] as usize].distance(positions[tet[b] as usize]))
        .sum::<f64>()
        / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Builtin, Perturbation, Scene};
    use crate::simulation::Settings;
    use arrows::{correction_arrows, tet_gradient_arrows};

    #[test]
    fn an_inverted_tet_is_red_and_its_volume_arrows_point_back_through_the_face() {
        let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
        let mut simulation = Simulation::new(&scene, Settings::default());
        simulation.perturb(Perturbation::Invert);
        let mut inverted = Vec::new();
        inverted_tets(simulation.positions(), simulation.tets(), &mut inverted);
        assert_eq!(inverted, [true]);
        let mut colours = Vec::new();
        particle_colours(4, simulation.tets(), &inverted, &mut colours);
        assert!(colours.iter().all(|&c| c == INVERTED));

        let mut arrows = Vec::new();
        tet_gradient_arrows(&simulation, 0, Family::VOLUME, 1.0, &mut arrows);
        assert_eq!(arrows.len(), 4);
        // Vertex 0 was reflected through the face (1, 2, 3): its arrow points back across it.
        let p = simulation.positions();
        let normal = (p[2] - p[1]).cross(p[3] - p[1]);
        let side = (p[0] - p[1]).dot(normal).signum();
        assert!(
            arrows[0].value.dot(normal) * side < 0.0,
            "the arrow crosses back over the face"
        );

        let size = tet_size(p, &simulation.tets()[0]);
        for (family, count) in [(Family::EDGES, 12), (Family::HEIGHT, 16)] {
            let mut arrows = Vec::new();
            tet_gradient_arrows(&simulation, 0, family, 2.0, &mut arrows);
            assert_eq!(arrows.len(), count, "{family:?}");
            let longest = arrows.iter().map(|a| a.vector.length()).fold(0.0, f64::max);
            assert!((longest - 2.0 * GRADIENT_ARROW_LENGTH * size).abs() < 1e-12);
            for a in &arrows {
                assert!(a.vector.cross(a.value).length() < 1e-12 && a.vector.dot(a.value) >= 0.0);
                let families = simulation.families();
                assert_eq!(a.quantity.colour(families), family_colour(families, family));
            }
        }
    }

    #[test]
    fn correction_arrows_are_the_last_substeps_displacements_times_the_gain() {
        let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
        let mut simulation = Simulation::new(&scene, Settings::default());
        simulation.perturb(Perturbation::Invert);
        let mut arrows = Vec::new();
        correction_arrows(&simulation, 0..4, 10.0, &mut arrows);
        assert!(arrows.is_empty(), "nothing projected yet");
        simulation.substep();
        correction_arrows(&simulation, 0..4, 10.0, &mut arrows);
        assert_eq!(arrows.len(), 4);
        for a in &arrows {
            assert_eq!(a.value, simulation.corrections()[a.particle as usize]);
            assert_eq!(a.vector, a.value * 10.0);
            assert_eq!(a.quantity.colour(simulation.families()), CORRECTION);
        }
    }

    /// The selected contact: ∇C of the contact family at the pair's four particles, the
    /// longest as long as a pending projection's, and nothing for a particle without contacts.
    #[test]
    fn the_selected_contact_gets_its_gradient_arrows() {
        let at = [0.3, 1.003, 0.2];
        let simulation = crate::simulation::contact::cube_on_cube(2, at, Settings::default(), 5);
        let contact = simulation.families().parse("contact").unwrap();
        let over = |i: usize| {
            let pairs = simulation.contacts_of(i);
            let first = pairs.first()?;
            simulation
                .contact_state(contact, *first)?
                .over
                .map(|_| *first)
        };
        let upper = simulation.bodies()[1].particles.clone();
        let (particle, pair) = (upper.map(|i| i as usize))
            .find_map(|i| over(i).map(|c| (i, c)))
            .expect("a particle of the upper cube over a triangle of the lower");
        let mut arrows = Vec::new();
        selected_contact_arrows(&simulation, particle, 1.0, 1.0, &mut arrows);
        let gradients: Vec<_> = (arrows.iter())
            .filter(|a| a.quantity == Quantity::Gradient(contact))
            .collect();
        let particles: Vec<u32> = gradients.iter().map(|a| a.particle).collect();
        assert_eq!(particles, simulation.contact_pairs()[pair]);
        let projection = simulation.projection(contact, pair);
        for (a, g) in gradients.iter().zip(projection.gradients) {
            assert_eq!(a.value, g);
        }
        let far = (0..simulation.positions().len()).find(|&i| simulation.contacts_of(i).is_empty());
        let mut none = Vec::new();
        selected_contact_arrows(&simulation, far.unwrap(), 1.0, 1.0, &mut none);
        assert!(none.is_empty());
    }

    #[test]
    fn small_meshes_show_all_faces_and_large_ones_their_surface() {
        let tet = Scene::builtin(Builtin::Tet, 1).unwrap();
        assert_eq!(display_faces(&tet.mesh).len(), 4);
        let cube = Scene::builtin(Builtin::Cube, 4).unwrap();
        assert_eq!(display_faces(&cube.mesh).len(), 6 * 4 * 4 * 2);
    }

    #[test]
    fn edge_strips_draw_every_edge_exactly_once_with_fewer_points() {
        let bunny_like = Scene::builtin(Builtin::Ball, 3).unwrap();
        for edges in [bunny_like.mesh.edges(), display_edges(&bunny_like.mesh)] {
            let strips = edge_strips(&edges);
            let mut drawn: Vec<[u32; 2]> = strips
                .iter()
                .flat_map(|s| s.windows(2).map(|w| [w[0].min(w[1]), w[0].max(w[1])]))
                .collect();
            drawn.sort_unstable();
            assert_eq!(drawn, edges, "every edge once, no other");
            let points: usize = strips.iter().map(Vec::len).sum();
            assert!(
                points < edges.len() * 2 * 3 / 4,
                "{points} points for {} edges",
                edges.len()
            );
        }
        assert!(edge_strips(&[]).is_empty());
    }

    #[test]
    fn large_meshes_draw_their_surface_edges() {
        let ball = Scene::builtin(Builtin::Ball, 3).unwrap();
        let surface = display_edges(&ball.mesh);
        assert!(surface.len() < ball.mesh.edges().len());
        // A closed triangulated surface has 3F/2 edges.
        assert_eq!(surface.len() * 2, display_faces(&ball.mesh).len() * 3);
        let tet = Scene::builtin(Builtin::Tet, 1).unwrap();
        assert_eq!(display_edges(&tet.mesh).len(), 6);
    }

    #[test]
    fn the_volume_colour_map_runs_from_red_to_white() {
        assert_eq!(volume_ratio_colour(-3.0), [255, 0, 0, 255]);
        assert_eq!(volume_ratio_colour(0.5), [255, 255, 0, 255]);
        assert_eq!(volume_ratio_colour(1.7), [255, 255, 255, 255]);
        assert_eq!(volume_ratio_colour(f64::NAN), [255, 0, 0, 255]);
    }
}
