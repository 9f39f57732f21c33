//! How a family's constraints lay on a tet mesh ([`Binding`]): one per edge, per tet, per tet
//! and vertex, per surface triangle, per surface hinge or per particle, and so how many a mesh
//! has and which particles each touches.

use crate::scene::mesh::{TET_EDGES, TetMesh};

/// `body` with `N` the constant arity `arity` (1 to 4; 4 above): the one place where a
/// binding's arity, a number at run time, becomes the const generic that a constraint's code is
/// compiled for. `for_arity!(arity, |N| f::<N>(x))`.
macro_rules! for_arity {
    ($arity:expr, |$n:ident| $body:expr) => {
        match $arity {
            1 => {
                const $n: usize = 1;
                $body
            }
            2 => {
                const $n: usize = 2;
                $body
            }
            3 => {
                const $n: usize = 3;
                $body
            }
            _ => {
                const $n: usize = 4;
                $body
            }
        }
    };
}
pub(crate) use for_arity;

/// How a family's constraints bind to a tet mesh, and so how many it has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binding {
    /// One constraint per edge of the mesh: (p0, p1), the edge's ends, smaller index first; in the
    /// order of [`crate::scene::mesh::TetMesh::edges`].
    Edges,
    /// One per tet: (p0, p1, p2, p3), the tet's corners in its own order.
    Tets,
    /// Four per tet, one per corner k: (p0, p1, p2, p3) with p1 = corner k, in the orders of
    /// [`super::height::tet_vertex_order`]; tet t's are constraints 4t..4t+4.
    TetVertices,
    /// One per triangle of the surface: (p0, p1, p2) wound so that (p1 − p0) × (p2 − p0) points
    /// out of the body ([`crate::scene::mesh::TetMesh::surface_faces`]).
    Triangles,
    /// One per edge of the surface that two surface triangles share: (p0, p1) the edge, as the
    /// first triangle (p0, p1, p2) winds it, p2 and p3 the wings, so that the second triangle
    /// is (p1, p0, p3), both wound outwards ([`crate::scene::mesh::TetMesh::surface_hinges`]).
    /// An edge of one surface triangle or of three or more (non-manifold) makes no hinge.
    Hinges,
    /// One per particle: (p0). A constraint file's `where` keeps those it chooses by their rest
    /// positions (a pin set, a handle, the particles above a plane); without one, every
    /// particle ([`crate::constraint_file::ConstraintFile::chooses`]).
    Particles,
    /// Found every frame rather than bound once: (p0, p1, p2, p3) with p0 a particle of a
    /// surface and (p1, p2, p3) a surface triangle it is about to meet, wound outwards, of
    /// another body or of its own away from p0 (`crate::simulation::contact`). It has no
    /// constraints on a mesh at rest.
    Contacts,
}

impl Binding {
    /// How many particles each of its constraints has.
    pub fn arity(self) -> usize {
        match self {
            Binding::Particles => 1,
            Binding::Edges => 2,
            Binding::Triangles => 3,
            Binding::Tets | Binding::TetVertices | Binding::Hinges | Binding::Contacts => 4,
        }
    }

    /// The particles of every constraint of this binding on `mesh`, flat: `arity` indices per
    /// constraint, in constraint order.
    pub fn particles(self, mesh: &TetMesh) -> Vec<u32> {
        match self {
            Binding::Edges => mesh.edges().into_iter().flatten().collect(),
            Binding::Tets => mesh.tets.iter().flatten().copied().collect(),
            Binding::Triangles => mesh.surface_faces().into_iter().flatten().collect(),
            Binding::Hinges => mesh.surface_hinges().into_iter().flatten().collect(),
            Binding::Particles => (0..mesh.positions.len() as u32).collect(),
            Binding::Contacts => Vec::new(),
            Binding::TetVertices => mesh
                .tets
                .iter()
                .flat_map(|t| {
                    super::height::tet_vertex_order()
                        .into_iter()
                        .flat_map(move |order| order.map(|k| t[k]))
                })
                .collect(),
        }
    }

    /// The constraints of this binding on tet `tet` (whose corners are `corners`), as indices
    /// among them; `edges` are the particles of an [`Binding::Edges`] family (sorted pairs,
    /// flat), which are looked up.
    pub fn of_tet<'a>(
        self,
        tet: usize,
        corners: [u32; 4],
        edges: &'a [u32],
    ) -> impl Iterator<Item = usize> + 'a {
        let (range, look_up) = match self {
            Binding::Edges => (0..0, true),
            Binding::Tets => (tet..tet + 1, false),
            Binding::TetVertices => (4 * tet..4 * tet + 4, false),
            // Of the surface, of single particles or of contacts, not of a tet.
            Binding::Triangles | Binding::Hinges | Binding::Particles | Binding::Contacts => {
                (0..0, false)
            }
        };
        let pairs = pairs(edges);
        let looked_up = TET_EDGES
            .iter()
            .filter(move |_| look_up)
            .filter_map(move |&(a, b)| {
                let key = [corners[a].min(corners[b]), corners[a].max(corners[b])];
                pairs.binary_search(&key).ok()
            });
        range.chain(looked_up)
    }
}

/// Flat pairs as pairs.
fn pairs(flat: &[u32]) -> &[[u32; 2]] {
    let (pairs, rest) = flat.as_chunks::<2>();
    debug_assert!(rest.is_empty(), "pairs come in twos");
    pairs
}
