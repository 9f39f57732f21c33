//! The body's surface as front ends draw it: the faces and edges shown, which tets are inverted,
//! and the colours of particles and faces.

use super::*;

/// Whether each tet is inverted (signed volume < 0), in tet order.
pub fn inverted_tets(positions: &[DVec3], tets: &[[u32; 4]], out: &mut Vec<bool>) {
    out.clear();
    out.extend(
        tets.iter()
            .map(|t| signed_volume(&t.map(|i| positions[i as usize])) < 0.0),
    );
}

/// Colours each particle that an active family on single particles holds (a pin or a hook of
/// a file, `applies_to = "particles"`) in that family's colour, where `particle_colours` gave
/// it [`HEALTHY`] (a particle of an inverted tet stays [`INVERTED`]).
pub fn held_particle_colours(simulation: &Simulation, out: &mut [Rgba]) {
    let families = simulation.families();
    let on_particles = |f: Family| families.binding(f) == crate::constraints::Binding::Particles;
    for family in (families.all()).filter(|&f| simulation.active()[f] && on_particles(f)) {
        let colour = family_colour(families, family);
        for &i in simulation.constraint_particles(family) {
            if out[i as usize] == HEALTHY {
                out[i as usize] = colour;
            }
        }
    }
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

/// The arrows of the contacts touching ([`crate::measures::metrics::Metrics::contacts`]), where
/// a family on contacts is active: at each touching particle, ∇ₚ₀C of the built-in contact (the
/// unit normal of the triangle it rests on, pointing out of the triangle's body), in the first
/// such family's colour, [`super::GRADIENT_ARROW_LENGTH`] mean rest edges long at `gain` 1.
/// Appended to `out`.
pub fn contact_arrows(simulation: &Simulation, gain: f64, out: &mut Vec<super::Arrow>) {
    let families = simulation.families();
    let active = simulation.active();
    let Some(family) = crate::simulation::contact::contact_families(families, active).next() else {
        return;
    };
    let positions = simulation.positions();
    let thickness = simulation.settings().contact.thickness;
    let length = gain * super::GRADIENT_ARROW_LENGTH * simulation.body().mean_edge;
    for pair in simulation.contact_pairs() {
        let p = pair.map(|i| positions[i as usize]);
        if crate::simulation::contact::project::over_triangle(p[0], [p[1], p[2], p[3]]).is_none() {
            continue;
        }
        let e = crate::constraints::contact::evaluate(&p, thickness);
        let touching = e.value + thickness <= crate::measures::metrics::TOUCHING * thickness;
        if !e.degenerate && touching {
            out.push(super::Arrow {
                quantity: super::Quantity::Gradient(family),
                particle: pair[0],
                origin: p[0],
                value: e.gradients[0],
                vector: e.gradients[0] * length,
            });
        }
    }
}

/// The arrows of the selected contact: for the nearest contact pair of `particle` that lies
/// over its triangle ([`Simulation::contacts_of`]), ∇C of each active family on contacts at its
/// four particles and the Δx the contact pass would give them
/// ([`super::projection_arrows`], as step-by-step mode draws a pending projection). None where
/// the particle has no such pair. Appended to `out`.
pub fn selected_contact_arrows(
    simulation: &Simulation,
    particle: usize,
    gain: f64,
    correction_gain: f64,
    out: &mut Vec<super::Arrow>,
) {
    let families = simulation.families();
    let Some(&pair) = simulation.contacts_of(particle).first() else {
        return;
    };
    for family in crate::simulation::contact::contact_families(families, simulation.active()) {
        let over = simulation.contact_state(family, pair).and_then(|s| s.over);
        if over.is_some() {
            let projection = simulation.projection(family, pair);
            let positions = simulation.positions();
            super::projection_arrows(families, positions, &projection, gain, correction_gain, out);
        }
    }
}
