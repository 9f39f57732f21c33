//! The layouts of the elements the active families bind to (edges, tets, (tet, vertex) pairs,
//! surface triangles and hinges, and each family's own particles), built from a simulation's body in the fast engine's particle
//! numbering, and the order each family's colours are projected in.

use super::batches::Layout;
use crate::constraints::{Binding, Families, Family, PerFamily};
use crate::simulation::Resolved;
use crate::simulation::state::Body;
use glam::Vec3A;

/// The layouts of the elements families bind to; every family of a binding shares that
/// binding's (each is empty when no active family uses it), except that a family on single
/// particles has its own: each file's `where` chooses its particles.
#[derive(Default)]
pub(super) struct Layouts {
    edges: Layout,
    tets: Layout,
    tet_vertices: Layout,
    triangles: Layout,
    hinges: Layout,
    /// Of each active family on single particles.
    particles: Vec<(Family, Layout)>,
    /// Of contacts: empty, since contacts are found every frame and projected apart from the
    /// sweep's layouts (`crate::simulation::contact`).
    contacts: Layout,
}

impl Layouts {
    /// The layouts the `active` families of `families` bind to on `body`, its particles
    /// renumbered by `renumber`, weighted by `inverse_masses` and sized by `rest_positions` (both
    /// in the new numbering).
    pub(super) fn new(
        families: &Families,
        active: &PerFamily<bool>,
        body: &Body,
        renumber: &[u32],
        (inverse_masses, rest_positions): (&[f32], &[Vec3A]),
    ) -> Layouts {
        let uses = |binding: Binding| active.families().any(|f| families.binding(f) == binding);
        let renumbered = |constraints: &[[u32; 4]]| -> Vec<[u32; 4]> {
            constraints
                .iter()
                .map(|c| c.map(|i| renumber[i as usize]))
                .collect()
        };
        let mut layouts = Layouts::default();
        if uses(Binding::Edges) {
            // In the order of the edge binding ([`Binding::particles`]), whose rest values they
            // are: the built-in edge family's, always built.
            let (pairs, _) = body.sets[Family::EDGES].all_particles().as_chunks::<2>();
            let edges: Vec<[u32; 2]> = pairs
                .iter()
                .map(|edge| edge.map(|i| renumber[i as usize]))
                .collect();
            layouts.edges = Layout::new(&edges, inverse_masses, rest_positions);
        }
        if uses(Binding::Contacts) {
            layouts.contacts = Layout::new::<4>(&[], inverse_masses, rest_positions);
        }
        if uses(Binding::Tets) {
            let tets = renumbered(&body.tets);
            layouts.tets = Layout::new(&tets, inverse_masses, rest_positions);
        }
        if uses(Binding::TetVertices) {
            // Each (tet, vertex) constraint is an element of its own, its particles in the
            // constraint's order ([`Binding::particles`]), coloured apart from its tet's others.
            let mesh = crate::scene::mesh::TetMesh {
                positions: Vec::new(),
                tets: body.tets.clone(),
            };
            let flat = Binding::TetVertices.particles(&mesh);
            let (constraints, _) = flat.as_chunks::<4>();
            let constraints = renumbered(constraints);
            // Role by role: every tet's first height, then every tet's second, …, so that a
            // tet's four heights take colours far apart (see `batches`).
            let n = constraints.len();
            let visit: Vec<usize> = (0..4).flat_map(|k| (k..n).step_by(4)).collect();
            layouts.tet_vertices =
                Layout::new_visiting(&constraints, visit, inverse_masses, rest_positions);
        }
        // The surface's triangles and hinges, in the order of their binding, as the sets of the
        // active families that bind to them hold them (whose rest values they are).
        let of_binding = |binding: Binding| {
            active
                .families()
                .find(|&f| families.binding(f) == binding)
                .map(|f| body.sets[f].all_particles())
        };
        if let Some(flat) = of_binding(Binding::Triangles) {
            let (triangles, _) = flat.as_chunks::<3>();
            let triangles: Vec<[u32; 3]> = triangles
                .iter()
                .map(|t| t.map(|i| renumber[i as usize]))
                .collect();
            layouts.triangles = Layout::new(&triangles, inverse_masses, rest_positions);
        }
        if let Some(flat) = of_binding(Binding::Hinges) {
            let (hinges, _) = flat.as_chunks::<4>();
            layouts.hinges = Layout::new(&renumbered(hinges), inverse_masses, rest_positions);
        }
        // Each family on single particles: one colour, since no two of its constraints share
        // a particle.
        for family in active
            .families()
            .filter(|&f| families.binding(f) == Binding::Particles)
        {
            let (chosen, _) = body.sets[family].all_particles().as_chunks::<1>();
            let chosen: Vec<[u32; 1]> = chosen
                .iter()
                .map(|p| p.map(|i| renumber[i as usize]))
                .collect();
            let layout = Layout::new(&chosen, inverse_masses, rest_positions);
            layouts.particles.push((family, layout));
        }
        layouts
    }

    /// The layout `family` (of `families`) uses.
    ///
    /// # Panics
    /// For a family on single particles that was not active when the layouts were built.
    pub(super) fn of(&self, families: &Families, family: Family) -> &Layout {
        match families.binding(family) {
            Binding::Edges => &self.edges,
            Binding::Tets => &self.tets,
            Binding::TetVertices => &self.tet_vertices,
            Binding::Triangles => &self.triangles,
            Binding::Hinges => &self.hinges,
            Binding::Contacts => &self.contacts,
            Binding::Particles => {
                let own = self.particles.iter().find(|(f, _)| *f == family);
                &own.expect("an active family's layout").1
            }
        }
    }

    /// Every one, for the families' weights.
    pub(super) fn all_mut(&mut self) -> impl Iterator<Item = &mut Layout> {
        [
            &mut self.edges,
            &mut self.tets,
            &mut self.tet_vertices,
            &mut self.triangles,
            &mut self.hinges,
        ]
        .into_iter()
        .chain(self.particles.iter_mut().map(|(_, layout)| layout))
    }

    /// Every one.
    pub(super) fn all(&self) -> impl Iterator<Item = &Layout> {
        [
            &self.edges,
            &self.tets,
            &self.tet_vertices,
            &self.triangles,
            &self.hinges,
        ]
        .into_iter()
        .chain(self.particles.iter().map(|(_, layout)| layout))
    }

    /// The order of each active family's colours that the settings ask for
    /// ([`crate::simulation::Settings::order_seed`]): empty (the layout's order) without a seed.
    pub(super) fn colour_orders(
        &self,
        families: &Families,
        resolved: &Resolved,
    ) -> PerFamily<Vec<u32>> {
        families.per_family(|family| {
            if !resolved.active[family] {
                return Vec::new();
            }
            let colours = self.of(families, family).colour_count();
            (resolved.settings)
                .projection_order(family, colours)
                .unwrap_or_default()
        })
    }
}
