//! Tetrahedral meshes: positions, tets, and what is derived from them (edges, surface faces).
//!
//! Loaders for TetGen (`.node`/`.ele`) and Gmsh (`.msh`, ASCII 2.2 and 4.1) live in `tetgen` and
//! [`gmsh`]; both hand their raw tets to [`TetMesh::new`], which checks and cleans them the same way.

pub mod gmsh;
pub mod tetgen;
mod text;

pub use text::MeshError;

use crate::constraints::volume::signed_volume;
use glam::DVec3;
use std::path::Path;

/// A tet mesh: particle positions and tets as four indices into them.
///
/// Every tet is positively oriented, (p1 − p0)·((p2 − p0)×(p3 − p0)) ≥ 0, and every position is
/// used by some tet.
#[derive(Clone, Debug, PartialEq)]
pub struct TetMesh {
    /// Particle positions.
    pub positions: Vec<DVec3>,
    /// Tets as indices into `positions`.
    pub tets: Vec<[u32; 4]>,
}

/// What [`TetMesh::new`] changed or noticed while cleaning a mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadReport {
    /// Tets whose signed rest volume was negative, reordered (two vertices swapped) to positive.
    pub reoriented_tets: usize,
    /// Tets with (nearly) zero rest volume: |V| ≤ 10⁻¹² · (longest edge)³.
    pub degenerate_tets: usize,
    /// Nodes used by no tet, removed.
    pub unused_nodes: usize,
    /// Other element kinds in the file (points, lines, triangles, …), ignored.
    pub ignored_elements: usize,
}

impl LoadReport {
    /// One line per notable fact, for people.
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        let mut say = |count: usize, what: &str| {
            if count > 0 {
                notes.push(format!("{count} {what}"));
            }
        };
        say(
            self.reoriented_tets,
            "tets with negative rest volume reordered to positive",
        );
        say(
            self.degenerate_tets,
            "tets with zero rest volume (kept, their constraints skip)",
        );
        say(self.unused_nodes, "nodes used by no tet removed");
        say(self.ignored_elements, "non-tet elements ignored");
        notes
    }
}

impl TetMesh {
    /// Builds a mesh from raw positions and tets: drops nodes no tet uses (renumbering the tets)
    /// and reorders each negatively oriented tet to positive. Indices must be in range and
    /// distinct within a tet; the loaders check that with file and line.
    pub fn new(positions: Vec<DVec3>, tets: Vec<[u32; 4]>) -> (TetMesh, LoadReport) {
        let mut report = LoadReport::default();
        let mut new_index = vec![u32::MAX; positions.len()];
        let mut kept = Vec::with_capacity(positions.len());
        for tet in &tets {
            for &i in tet {
                if new_index[i as usize] == u32::MAX {
                    new_index[i as usize] = 0;
                }
            }
        }
        for (i, p) in positions.iter().enumerate() {
            if new_index[i] == u32::MAX {
                report.unused_nodes += 1;
            } else {
                new_index[i] = kept.len() as u32;
                kept.push(*p);
            }
        }
        let mut tets: Vec<[u32; 4]> = tets
            .iter()
            .map(|t| t.map(|i| new_index[i as usize]))
            .collect();
        for tet in &mut tets {
            let corners = tet.map(|i| kept[i as usize]);
            let volume = signed_volume(&corners);
            let longest = longest_edge(corners.iter().copied());
            if volume.abs() <= 1e-12 * longest * longest * longest {
                report.degenerate_tets += 1;
            } else if volume < 0.0 {
                tet.swap(2, 3);
                report.reoriented_tets += 1;
            }
        }
        (
            TetMesh {
                positions: kept,
                tets,
            },
            report,
        )
    }

    /// Loads a TetGen `.node`/`.ele` pair (either path; the other is found beside it) or a Gmsh
    /// `.msh` file, chosen by the extension.
    pub fn load(path: &Path) -> Result<(TetMesh, LoadReport), MeshError> {
        match path.extension().and_then(|e| e.to_str()) {
            Some("node") | Some("ele") => tetgen::load(path),
            Some("msh") => gmsh::load(path),
            _ => Err(MeshError::whole_file(
                path,
                "unknown mesh format: expected a .node, .ele or .msh file",
            )),
        }
    }

    /// The unique edges of all tets, each as (smaller index, larger index), sorted.
    pub fn edges(&self) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = Vec::with_capacity(self.tets.len() * 6);
        for t in &self.tets {
            for (a, b) in TET_EDGES {
                let (i, j) = (t[a], t[b]);
                edges.push([i.min(j), i.max(j)]);
            }
        }
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// Per particle, the longest rest edge that ends at it (0 for a particle of no tet): the
    /// size a constraint on that particle alone is measured in.
    ///
    /// ```
    /// # use glam::DVec3;
    /// # use tetlab_core::scene::mesh::TetMesh;
    /// let mesh = TetMesh {
    ///     positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
    ///     tets: vec![[0, 1, 2, 3]],
    /// };
    /// let at = mesh.longest_edge_at();
    /// assert_eq!(at[0], 1.0, "the origin's edges are the axes");
    /// assert_eq!(at[1], 2f64.sqrt());
    /// ```
    pub fn longest_edge_at(&self) -> Vec<f64> {
        let mut longest = vec![0.0f64; self.positions.len()];
        for [i, j] in self.edges() {
            let length = self.positions[i as usize].distance(self.positions[j as usize]);
            for k in [i, j] {
                longest[k as usize] = longest[k as usize].max(length);
            }
        }
        longest
    }

    /// The boundary triangles: faces that belong to exactly one tet, wound so that their normal
    /// (b − a)×(c − a) points out of the body. In tet order, then face order, so the result is
    /// deterministic.
    pub fn surface_faces(&self) -> Vec<[u32; 3]> {
        self.surface_faces_with_tets()
            .into_iter()
            .map(|(face, _)| face)
            .collect()
    }

    /// [`TetMesh::surface_faces`], each with the tet it belongs to.
    pub(crate) fn surface_faces_with_tets(&self) -> Vec<([u32; 3], u32)> {
        let mut uses: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
        for tet in &self.tets {
            for face in tet_faces(tet) {
                *uses.entry(sorted(face)).or_insert(0) += 1;
            }
        }
        self.tets
            .iter()
            .enumerate()
            .flat_map(|(t, tet)| tet_faces(tet).map(|face| (face, t as u32)))
            .filter(|(face, _)| uses[&sorted(*face)] == 1)
            .collect()
    }

    /// The hinges of the surface: for each edge that exactly two surface triangles share,
    /// `[a, b, c, d]`, with a → b the edge as the first of them (a, b, c) winds it (faces in
    /// [`TetMesh::surface_faces`]'s order), c its third corner and d the other's, which winds the
    /// edge b → a: (b, a, d). Sorted, so the result is deterministic. A surface edge of one
    /// triangle (an open surface, which a tet mesh's is not) or of three or more (a non-manifold
    /// edge, where two bodies touch along it) makes no hinge.
    ///
    /// ```
    /// use glam::DVec3;
    /// use tetlab_core::scene::mesh::TetMesh;
    /// // One tet: four faces, six edges, each shared by two faces.
    /// let tet = TetMesh { positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z], tets: vec![[0, 1, 2, 3]] };
    /// let hinges = tet.surface_hinges();
    /// assert_eq!(hinges.len(), 6);
    /// // Each wing is the corner off its edge, and the two wings differ.
    /// assert!(hinges.iter().all(|h| h[2] != h[3] && !h[..2].contains(&h[2]) && !h[..2].contains(&h[3])));
    /// ```
    pub fn surface_hinges(&self) -> Vec<[u32; 4]> {
        let faces = self.surface_faces();
        let mut by_edge: std::collections::HashMap<[u32; 2], Vec<(usize, [u32; 3])>> =
            std::collections::HashMap::new();
        for (f, face) in faces.iter().enumerate() {
            for k in 0..3 {
                let (a, b, c) = (face[k], face[(k + 1) % 3], face[(k + 2) % 3]);
                by_edge
                    .entry([a.min(b), a.max(b)])
                    .or_default()
                    .push((f, [a, b, c]));
            }
        }
        let mut hinges: Vec<[u32; 4]> = by_edge
            .into_values()
            .filter(|sides| sides.len() == 2)
            .map(|mut sides| {
                sides.sort_unstable();
                let ([a, b, c], [_, _, d]) = (sides[0].1, sides[1].1);
                [a, b, c, d]
            })
            .collect();
        hinges.sort_unstable();
        hinges
    }

    /// The positions of tet `t`'s four corners.
    #[inline]
    pub fn corners(&self, t: usize) -> [DVec3; 4] {
        self.tets[t].map(|i| self.positions[i as usize])
    }
}

/// The six edges of a tet as pairs of corner numbers.
pub const TET_EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// The four faces of a positively oriented tet (a, b, c, d), face k opposite corner k, each wound
/// so that its normal points away from that corner (out of the tet).
#[inline]
pub(crate) fn tet_faces(t: &[u32; 4]) -> [[u32; 3]; 4] {
    let [a, b, c, d] = *t;
    [[b, c, d], [a, d, c], [a, b, d], [a, c, b]]
}

fn sorted(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// The longest distance between two of `points` (an edge's length, a tet's longest edge): the
/// size of an element.
pub(crate) fn longest_edge(points: impl Iterator<Item = DVec3> + Clone) -> f64 {
    let mut longest: f64 = 0.0;
    for (k, a) in points.clone().enumerate() {
        for b in points.clone().skip(k + 1) {
            longest = longest.max(a.distance(b));
        }
    }
    longest
}

/// The box around `positions`: lowest and highest corner.
pub fn bounds(positions: &[DVec3]) -> (DVec3, DVec3) {
    positions.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}
