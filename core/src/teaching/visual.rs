//! What to draw, derived from a simulation once for every front end: the recorder logs it and
//! the GUI paints it, so both show the same arrows in the same colours.

use crate::constraints::Family;
use crate::constraints::volume::signed_volume;
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
pub fn family_colour(family: Family) -> Rgba {
    family.row().colour
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

/// Whether each tet is inverted (signed volume < 0), in tet order.
pub fn inverted_tets(positions: &[DVec3], tets: &[[u32; 4]], out: &mut Vec<bool>) {
    out.clear();
    out.extend(
        tets.iter()
            .map(|t| signed_volume(&t.map(|i| positions[i as usize])) < 0.0),
    );
}

/// A particle's colour: [`INVERTED`] when it belongs to an inverted tet, [`HEALTHY`] otherwise.
pub fn particle_colours(
    particles: usize,
    tets: &[[u32; 4]],
    inverted: &[bool],
    out: &mut Vec<Rgba>,
) {
    out.clear();
    out.resize(particles, HEALTHY);
    for (tet, &bad) in tets.iter().zip(inverted) {
        if bad {
            for &i in tet {
                out[i as usize] = INVERTED;
            }
        }
    }
}

/// The triangles worth drawing: every face of every tet when the mesh is small (so a single tet
/// or a small block is seen whole), the boundary surface otherwise.
pub fn display_faces(mesh: &TetMesh) -> Vec<[u32; 3]> {
    faces_with_tets(mesh, mesh.tets.len() <= ALL_FACES_UP_TO)
        .into_iter()
        .map(|(f, _)| f)
        .collect()
}

/// Every face of every tet (`all`), or the boundary faces only, each with the tet it belongs to,
/// wound outward from that tet, in tet order.
pub fn faces_with_tets(mesh: &TetMesh, all: bool) -> Vec<([u32; 3], u32)> {
    if all {
        let faces = mesh.tets.iter().enumerate();
        faces
            .flat_map(|(t, tet)| crate::scene::mesh::tet_faces(tet).map(|f| (f, t as u32)))
            .collect()
    } else {
        mesh.surface_faces_with_tets()
    }
}

/// Meshes with at most this many tets are drawn with all their faces and edges.
pub const ALL_FACES_UP_TO: usize = 64;

/// The edges worth drawing, to go with [`display_faces`]: every edge of a small mesh, the edges of
/// the boundary surface otherwise. Sorted pairs (smaller index first), sorted.
pub fn display_edges(mesh: &TetMesh) -> Vec<[u32; 2]> {
    if mesh.tets.len() <= ALL_FACES_UP_TO {
        return mesh.edges();
    }
    let mut edges: Vec<[u32; 2]> = mesh
        .surface_faces()
        .iter()
        .flat_map(|f| [[f[0], f[1]], [f[1], f[2]], [f[2], f[0]]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// Chains edges into polylines that draw every edge exactly once: a polyline of k points draws
/// k − 1 edges, so a mesh's edges need far fewer points than two per edge. Greedy: each walk
/// starts at the lowest vertex with an odd number of unused edges (or any unused edge), and follows
/// unused edges, lowest neighbour first, until it is stuck. Deterministic.
pub fn edge_strips(edges: &[[u32; 2]]) -> Vec<Vec<u32>> {
    let vertices = edges
        .iter()
        .flatten()
        .map(|&v| v as usize + 1)
        .max()
        .unwrap_or(0);
    let mut neighbours: Vec<Vec<(u32, usize)>> = vec![Vec::new(); vertices];
    for (e, &[a, b]) in edges.iter().enumerate() {
        neighbours[a as usize].push((b, e));
        neighbours[b as usize].push((a, e));
    }
    for list in &mut neighbours {
        list.sort_unstable();
    }
    let mut used = vec![false; edges.len()];
    let mut unused_degree: Vec<usize> = neighbours.iter().map(Vec::len).collect();
    let mut next = vec![0usize; vertices];
    let mut strips = Vec::new();
    let starts = (0..vertices)
        .filter(|&v| unused_degree[v] % 2 == 1)
        .chain(0..vertices)
        .collect::<Vec<_>>();
    for start in starts {
        while unused_degree[start] > 0 {
            let mut strip = vec![start as u32];
            let mut at = start;
            while let Some(&(to, e)) = neighbours[at][next[at]..].iter().find(|(_, e)| !used[*e]) {
                used[e] = true;
                unused_degree[at] -= 1;
                unused_degree[to as usize] -= 1;
                while next[at] < neighbours[at].len() && used[neighbours[at][next[at]].1] {
                    next[at] += 1;
                }
                strip.push(to);
                at = to as usize;
            }
            strips.push(strip);
        }
    }
    strips
}

/// The colour of the correction arrows (Δp of the last substep): magenta.
pub const CORRECTION: Rgba = [200, 50, 200, 255];

/// What an arrow shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// ∇ₚC of one constraint of a family, as the solver projects it.
    Gradient(Family),
    /// For a family read from a constraint file that gives its own gradient: the gradient the
    /// solver does not use (yours, or AD's when the file asks for its own to be used), drawn only
    /// at particles where it differs from the one in use.
    Disagreeing(Family),
    /// Δp, the correction the last substep's projections made (see
    /// [`Simulation::corrections`]).
    Correction,
}

impl Quantity {
    /// The arrow colour: [`family_colour`] for gradients, the same lightened halfway to white
    /// for the disagreeing one, [`CORRECTION`] for corrections.
    pub fn colour(self) -> Rgba {
        match self {
            Quantity::Gradient(family) => family_colour(family),
            Quantity::Disagreeing(family) => {
                let [r, g, b, a] = family_colour(family);
                let light = |c: u8| c + (255 - c) / 2;
                [light(r), light(g), light(b), a]
            }
            Quantity::Correction => CORRECTION,
        }
    }

    /// What it is, for legends: "grad C: heights", "grad C: my-height, yours, where it differs",
    /// "dp".
    pub fn label(self) -> String {
        match self {
            Quantity::Gradient(family) => match family.file() {
                Some(file) if file.use_gradient => format!("grad C: {} (yours)", family.name()),
                Some(_) => format!("grad C: {} (AD)", family.name()),
                None => format!("grad C: {}", family.row().label),
            },
            Quantity::Disagreeing(family) => {
                let other = Quantity::disagreeing_name(family);
                format!("grad C: {}, {other}, where it differs", family.name())
            }
            Quantity::Correction => "dp".to_owned(),
        }
    }
}

impl Quantity {
    /// Which gradient the [`Quantity::Disagreeing`] arrows of `family` show: "yours", or "AD"
    /// when the file asks the solver to use its own (`use_gradient`).
    pub fn disagreeing_name(family: Family) -> &'static str {
        match family.file() {
            Some(file) if file.use_gradient => "AD",
            _ => "yours",
        }
    }

    /// The gradient quantities a family's arrows can show: its ∇C, and for a constraint file
    /// that gives its own gradient, the one not in use ([`Quantity::Disagreeing`]).
    pub fn of_family(family: Family) -> impl Iterator<Item = Quantity> {
        let gives = family
            .file()
            .is_some_and(|file| (0..file.arity()).any(|k| file.gives_gradient(k)));
        [Quantity::Gradient(family)]
            .into_iter()
            .chain(gives.then_some(Quantity::Disagreeing(family)))
    }
}

/// The relative difference (to the largest gradient of the constraint) from which a
/// [`Quantity::Disagreeing`] arrow is drawn.
pub const DISAGREEMENT: f64 = 1e-6;

/// The [`Quantity::Disagreeing`] arrows of one projection of a file family: at each particle the
/// file gives a gradient for, the gradient the solver does not use, where it differs from the
/// one it uses by more than [`DISAGREEMENT`]. Appends to `out`, unscaled.
fn disagreeing_arrows(positions: &[DVec3], projection: &Projection, out: &mut Vec<Arrow>) {
    let Some(file) = projection.family.file() else {
        return;
    };
    if projection.degenerate || !(0..projection.len).any(|k| file.gives_gradient(k)) {
        return;
    }
    let points: [DVec3; 4] = std::array::from_fn(|k| {
        positions[projection.particles[k.min(projection.len - 1)] as usize]
    });
    let other = match projection.len {
        2 => {
            let e = file.evaluate_by(&[points[0], points[1]], projection.rest, !file.use_gradient);
            [e.gradients[0], e.gradients[1], DVec3::ZERO, DVec3::ZERO]
        }
        _ => {
            file.evaluate_by(&points, projection.rest, !file.use_gradient)
                .gradients
        }
    };
    let used = &projection.gradients[..projection.len];
    let scale = used.iter().map(|g| g.length()).fold(0.0, f64::max);
    for (k, (&particle, &gradient)) in projection.particles().iter().zip(&other).enumerate() {
        let differs = (gradient - used[k]).length() > DISAGREEMENT * scale;
        if file.gives_gradient(k) && differs {
            out.push(Arrow {
                quantity: Quantity::Disagreeing(projection.family),
                particle,
                origin: positions[particle as usize],
                value: gradient,
                vector: DVec3::ZERO,
            });
        }
    }
}

/// One arrow at one particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arrow {
    /// What it shows.
    pub quantity: Quantity,
    /// The particle the arrow starts at.
    pub particle: u32,
    /// Where it starts: the particle's position.
    pub origin: DVec3,
    /// The quantity itself (∇ₚC, or Δp in metres), unscaled.
    pub value: DVec3,
    /// What to draw from `origin`: `value` times the arrow set's scale.
    pub vector: DVec3,
}

/// The longest gradient arrow of a family on a tet at gain 1, as a fraction of the tet's mean edge
/// length ([`tet_size`]).
pub const GRADIENT_ARROW_LENGTH: f64 = 0.4;

/// The gradient arrows of `family` on tet `tet`: ∇ₚC at each particle p of each of the family's
/// constraints on that tet — 6 edges × 2 particles, 4 heights × 4 particles, or 1 volume × 4
/// particles — and, for a constraint file that gives its own gradient, the one not in use where
/// it differs ([`Quantity::Disagreeing`]). Degenerate constraints have no arrows. Gradients of different families have
/// different units (1, 1 and m²), so each family is scaled on its own: its longest arrow on the tet
/// is drawn `gain` × [`GRADIENT_ARROW_LENGTH`] × the tet's size long. Appends to `out`.
pub fn tet_gradient_arrows(
    simulation: &Simulation,
    tet: usize,
    family: Family,
    gain: f64,
    out: &mut Vec<Arrow>,
) {
    let positions = simulation.positions();
    let first = out.len();
    for c in simulation.tet_constraints(tet, family) {
        let projection = simulation.projection(family, c);
        if projection.degenerate {
            continue;
        }
        for (&particle, &gradient) in projection.particles().iter().zip(&projection.gradients) {
            out.push(Arrow {
                quantity: Quantity::Gradient(family),
                particle,
                origin: positions[particle as usize],
                value: gradient,
                vector: DVec3::ZERO,
            });
        }
        disagreeing_arrows(positions, &projection, out);
    }
    let length = gain * GRADIENT_ARROW_LENGTH * tet_size(positions, &simulation.tets()[tet]);
    scale_to_longest(&mut out[first..], length);
}

/// Sets each arrow's vector to its value times one factor, chosen so the longest is `length`.
fn scale_to_longest(arrows: &mut [Arrow], length: f64) {
    let longest = arrows.iter().map(|a| a.value.length()).fold(0.0, f64::max);
    let scale = if longest > 0.0 { length / longest } else { 0.0 };
    for arrow in arrows {
        arrow.vector = arrow.value * scale;
    }
}

/// The arrows of one projection (the one step-by-step mode is about to make): ∇ₚC at each of its
/// particles, the longest drawn `gain` × [`GRADIENT_ARROW_LENGTH`] × the mean distance between
/// them, and the Δx it will apply, `correction_gain` times its true length. Appends to `out`.
pub fn projection_arrows(
    positions: &[DVec3],
    projection: &Projection,
    gain: f64,
    correction_gain: f64,
    out: &mut Vec<Arrow>,
) {
    let particles = projection.particles();
    let point = |k: usize| positions[particles[k] as usize];
    let mut size = 0.0;
    let mut pairs = 0;
    for a in 0..particles.len() {
        for b in a + 1..particles.len() {
            size += point(a).distance(point(b));
            pairs += 1;
        }
    }
    let size = size / pairs.max(1) as f64;
    let first = out.len();
    if !projection.degenerate {
        for (&particle, &gradient) in particles.iter().zip(&projection.gradients) {
            out.push(Arrow {
                quantity: Quantity::Gradient(projection.family),
                particle,
                origin: positions[particle as usize],
                value: gradient,
                vector: DVec3::ZERO,
            });
        }
        disagreeing_arrows(positions, projection, out);
    }
    scale_to_longest(&mut out[first..], gain * GRADIENT_ARROW_LENGTH * size);
    for (&particle, &delta) in particles.iter().zip(&projection.delta_x) {
        out.extend(correction_arrow(
            positions,
            particle,
            delta,
            correction_gain,
        ));
    }
}

/// The arrow of a displacement `delta` at `particle`, `gain` times its true length; none for a
/// zero displacement.
fn correction_arrow(positions: &[DVec3], particle: u32, delta: DVec3, gain: f64) -> Option<Arrow> {
    (delta != DVec3::ZERO).then(|| Arrow {
        quantity: Quantity::Correction,
        particle,
        origin: positions[particle as usize],
        value: delta,
        vector: delta * gain,
    })
}

/// The correction arrows of `particles`: Δp of the last substep at each, drawn `gain` times its
/// true length (Δp is a displacement, in the scene's units). Zero corrections have no arrow.
/// Appends to `out`.
pub fn correction_arrows(
    simulation: &Simulation,
    particles: impl IntoIterator<Item = u32>,
    gain: f64,
    out: &mut Vec<Arrow>,
) {
    let positions = simulation.positions();
    let corrections = simulation.corrections();
    for particle in particles {
        let delta = corrections[particle as usize];
        out.extend(correction_arrow(positions, particle, delta, gain));
    }
}

/// Whose arrows are shown: no tet's, one tet's (the selected one), or every tet's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArrowSelection {
    /// No arrows.
    None,
    /// The arrows of one tet: ∇C of each active family's constraints on it, Δp at its corners.
    Tet(usize),
    /// The arrows of every tet, and Δp at every particle.
    AllTets,
}

/// The arrows of `selection`, as the workbench draws them and the recorder logs them: the
/// gradient arrows of every active family ([`tet_gradient_arrows`], scaled by
/// `gradient_gain`; none when it is `None`), then Δp of the last substep at the particles
/// ([`correction_arrows`], `correction_gain` times its length; none when it is `None`).
/// Appends to `out`.
pub fn selected_arrows(
    simulation: &Simulation,
    selection: ArrowSelection,
    gradient_gain: Option<f64>,
    correction_gain: Option<f64>,
    out: &mut Vec<Arrow>,
) {
    let tets = match selection {
        ArrowSelection::None => return,
        ArrowSelection::Tet(tet) => tet..tet + 1,
        ArrowSelection::AllTets => 0..simulation.tets().len(),
    };
    if let Some(gain) = gradient_gain {
        let active = simulation.settings().active;
        for family in active.families() {
            for tet in tets.clone() {
                tet_gradient_arrows(simulation, tet, family, gain, out);
            }
        }
    }
    if let Some(gain) = correction_gain {
        match selection {
            ArrowSelection::Tet(tet) => {
                correction_arrows(simulation, simulation.tets()[tet], gain, out);
            }
            _ => {
                let particles = 0..simulation.positions().len() as u32;
                correction_arrows(simulation, particles, gain, out);
            }
        }
    }
}

/// The diagonal of [`bounds`]: the natural length scale for drawing a body (at least 10⁻⁶).
pub fn body_size(positions: &[DVec3]) -> f64 {
    let (lo, hi) = bounds(positions);
    (hi - lo).length().max(1e-6)
}

/// The mean edge length of tet `tet`: the natural length scale for drawing on it.
pub fn tet_size(positions: &[DVec3], tet: &[u32; 4]) -> f64 {
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
                assert_eq!(a.quantity.colour(), family_colour(family));
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
            assert_eq!(a.quantity.colour(), CORRECTION);
        }
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
