//! What contact is found on: a body's surface ([`ContactSurface`]), its triangles wound
//! outwards and its particles, and which particles are neighbours in the mesh, so that a
//! particle is never held off the triangles around it.

use crate::scene::mesh::{TET_EDGES, TetMesh};

/// The surface of a tet mesh as contact sees it: every surface triangle, wound so that
/// (p1 − p0) × (p2 − p0) points out of its body; every particle on the surface; and for each
/// particle its neighbours (the particles an edge of a tet joins it to).
///
/// A particle and a triangle of its own body make a contact only when the particle is neither a
/// corner of the triangle nor a neighbour of one ([`ContactSurface::may_touch`]): those are
/// always within a tet's size of the triangle, and their closeness is the body's shape, not a
/// collision.
///
/// ```
/// use tetlab_core::scene::{Builtin, Scene};
/// use tetlab_core::simulation::contact::ContactSurface;
/// let cube = Scene::builtin(Builtin::Cube, 2).unwrap();
/// let surface = ContactSurface::of(&cube.mesh.tets, cube.mesh.positions.len());
/// // 2 × 2 × 2 cubes: 6 faces of 4 squares of 2 triangles; the 26 particles outside the centre.
/// assert_eq!(surface.triangles.len(), 48);
/// assert_eq!(surface.particles.len(), 26);
/// // A corner of a triangle never touches it.
/// let t = surface.triangles[0];
/// assert!(!surface.may_touch(t[0], t));
/// ```
#[derive(Clone, Debug, Default)]
pub struct ContactSurface {
    /// The surface triangles, wound outwards.
    pub triangles: Vec<[u32; 3]>,
    /// The particles on the surface, in increasing order.
    pub particles: Vec<u32>,
    /// Where each particle's neighbours start in [`ContactSurface::neighbours`] (one more entry
    /// than particles).
    offsets: Vec<u32>,
    /// Each particle's neighbours, in increasing order.
    neighbours: Vec<u32>,
}

impl ContactSurface {
    /// The surface of the mesh of `particle_count` particles and `tets`.
    pub fn of(tets: &[[u32; 4]], particle_count: usize) -> ContactSurface {
        let mesh = TetMesh {
            positions: Vec::new(),
            tets: tets.to_vec(),
        };
        let triangles = mesh.surface_faces();
        let mut particles: Vec<u32> = triangles.iter().flatten().copied().collect();
        particles.sort_unstable();
        particles.dedup();
        let mut pairs: Vec<[u32; 2]> = tets
            .iter()
            .flat_map(|t| {
                TET_EDGES
                    .iter()
                    .flat_map(|&(a, b)| [[t[a], t[b]], [t[b], t[a]]])
            })
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0u32; particle_count + 1];
        for &[a, _] in &pairs {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..particle_count {
            offsets[i + 1] += offsets[i];
        }
        let neighbours = pairs.iter().map(|&[_, b]| b).collect();
        ContactSurface {
            triangles,
            particles,
            offsets,
            neighbours,
        }
    }

    /// Whether particles `a` and `b` are joined by an edge of a tet.
    pub fn are_neighbours(&self, a: u32, b: u32) -> bool {
        let range = self.offsets[a as usize] as usize..self.offsets[a as usize + 1] as usize;
        self.neighbours[range].binary_search(&b).is_ok()
    }

    /// Whether `particle` may make a contact with `triangle`: it is not one of its corners, nor a
    /// neighbour of one.
    pub fn may_touch(&self, particle: u32, triangle: [u32; 3]) -> bool {
        triangle
            .iter()
            .all(|&corner| corner != particle && !self.are_neighbours(particle, corner))
    }
}
