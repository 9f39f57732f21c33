//! The layouts of the elements the active families bind to (edges, tets, (tet, vertex) pairs,
//! surface triangles and hinges, and each family's own particles), built from a simulation's body in the fast engine's particle
//! numbering, and the order each family's colours are projected in.

use super::batches::Layout;
use crate::constraints::{Binding, Families, Family, PerFamily};
use crate::simulation::Resolved;
use crate::simulation::state::Body;
use glam::Vec3A;

/// The layouts of the elements families bind to; every family of a binding shares that
/// binding's (each is empty when no active family uses it), except a family whose elements are
/// not the binding's whole list: one on single particles (each file's `where` chooses its
/// particles), or one that some bodies of the scene do not take
/// ([`crate::scene::SceneBody::constraints`]); each such has its own.
#[derive(Default)]
pub(in crate::simulation) struct Layouts {
    edges: Layout,
    tets: Layout,
    tet_vertices: Layout,
    triangles: Layout,
    hinges: Layout,
    /// Of each active family that has its own elements.
    own: Vec<(Family, Layout)>,
    /// Of contacts: empty, since contacts are found every frame and projected apart from the
    /// sweep's layouts (`crate::simulation::contact`).
    contacts: Layout,
}

impl Layouts {
    /// The layouts the `active` families of `families` bind to on `body`, its particles
    /// renumbered by `renumber`, weighted by `inverse_masses` and sized by `rest_positions` (both
    /// in the new numbering). Each is built from the constraints of a family as its set holds
    /// them (whose rest values they are, in the binding's order), so that element e is
    /// constraint e of every family that uses the layout.
    pub(super) fn new(
        families: &Families,
        active: &PerFamily<bool>,
        body: &Body,
        renumber: &[u32],
        masses: (&[f32], &[Vec3A]),
    ) -> Layouts {
        let mut layouts = Layouts::default();
        // The binding's whole list: of a family laid on every body (a file's is).
        let whole = |f: Family| body.sets[f].is_whole();
        for binding in [
            Binding::Edges,
            Binding::Tets,
            Binding::TetVertices,
            Binding::Triangles,
            Binding::Hinges,
        ] {
            let users = || {
                active
                    .families()
                    .filter(move |&f| families.binding(f) == binding)
            };
            let Some(first) = users().find(|&f| whole(f)).or_else(|| users().next()) else {
                continue;
            };
            let shared = body.sets[first].all_particles();
            *layouts.shared_mut(binding) = layout(binding, shared, renumber, masses);
            for family in users().filter(|&f| body.sets[f].all_particles() != shared) {
                let flat = body.sets[family].all_particles();
                (layouts.own).push((family, layout(binding, flat, renumber, masses)));
            }
        }
        if active
            .families()
            .any(|f| families.binding(f) == Binding::Contacts)
        {
            layouts.contacts = Layout::new::<4>(&[], masses.0, masses.1);
        }
        // Each family on single particles: one colour, since no two of its constraints share
        // a particle.
        for family in active
            .families()
            .filter(|&f| families.binding(f) == Binding::Particles)
        {
            let flat = body.sets[family].all_particles();
            let own = layout(Binding::Particles, flat, renumber, masses);
            layouts.own.push((family, own));
        }
        layouts
    }

    /// The layout every family of `binding` shares, unless it has its own.
    fn shared_mut(&mut self, binding: Binding) -> &mut Layout {
        match binding {
            Binding::Edges => &mut self.edges,
            Binding::Tets => &mut self.tets,
            Binding::TetVertices => &mut self.tet_vertices,
            Binding::Triangles => &mut self.triangles,
            Binding::Hinges => &mut self.hinges,
            Binding::Contacts | Binding::Particles => &mut self.contacts,
        }
    }

    /// The layout `family` (of `families`) uses.
    ///
    /// # Panics
    /// For a family on single particles that was not active when the layouts were built.
    pub(in crate::simulation) fn of(&self, families: &Families, family: Family) -> &Layout {
        if let Some((_, own)) = self.own.iter().find(|(f, _)| *f == family) {
            return own;
        }
        match families.binding(family) {
            Binding::Edges => &self.edges,
            Binding::Tets => &self.tets,
            Binding::TetVertices => &self.tet_vertices,
            Binding::Triangles => &self.triangles,
            Binding::Hinges => &self.hinges,
            Binding::Contacts => &self.contacts,
            Binding::Particles => panic!("an active family's layout"),
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
        .chain(self.own.iter_mut().map(|(_, layout)| layout))
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
        .chain(self.own.iter().map(|(_, layout)| layout))
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

/// The layout of the elements `flat` (in the simulation's numbering, the binding's arity each)
/// of `binding`, renumbered by `renumber`, weighted and sized by `masses`.
fn layout(binding: Binding, flat: &[u32], renumber: &[u32], masses: (&[f32], &[Vec3A])) -> Layout {
    fn renumbered<const N: usize>(flat: &[u32], renumber: &[u32]) -> Vec<[u32; N]> {
        let (elements, _) = flat.as_chunks::<N>();
        (elements.iter())
            .map(|e| e.map(|i| renumber[i as usize]))
            .collect()
    }
    let (inverse_masses, rest_positions) = masses;
    match binding {
        Binding::Particles => Layout::new(
            &renumbered::<1>(flat, renumber),
            inverse_masses,
            rest_positions,
        ),
        Binding::Edges => Layout::new(
            &renumbered::<2>(flat, renumber),
            inverse_masses,
            rest_positions,
        ),
        Binding::Triangles => Layout::new(
            &renumbered::<3>(flat, renumber),
            inverse_masses,
            rest_positions,
        ),
        Binding::TetVertices => {
            // Each (tet, vertex) constraint is an element of its own, its particles in the
            // constraint's order ([`Binding::particles`]), coloured apart from its tet's others:
            // role by role, every tet's first height, then every tet's second, …, so that a
            // tet's four heights take colours far apart (see `batches`).
            let constraints = renumbered::<4>(flat, renumber);
            let n = constraints.len();
            let visit: Vec<usize> = (0..4).flat_map(|k| (k..n).step_by(4)).collect();
            Layout::new_visiting(&constraints, visit, inverse_masses, rest_positions)
        }
        Binding::Tets | Binding::Hinges | Binding::Contacts => Layout::new(
            &renumbered::<4>(flat, renumber),
            inverse_masses,
            rest_positions,
        ),
    }
}
