//! Scenes: a rest mesh plus which particles are pinned. Built-in scenes are generated in code;
//! any TetGen or Gmsh file can be loaded as a scene, and a scene file (TOML) places several
//! bodies, each launched with its own velocity ([`SceneBody`]). [`Perturbation`]s deform a scene's current
//! positions to set up an experiment (invert one tet, mirror the body, flatten it, scramble it). [`mesh`]
//! holds the tet mesh and its file formats.

mod adding;
mod bend;
pub mod mesh;
mod scene_file;
mod shipped;
pub use bend::Bend;
pub use scene_file::{MAX_PLACEMENT, SceneBody};
pub use shipped::{SHIPPED, ShippedScene};

use crate::constraints::volume::signed_volume;
use crate::input::limits;
use crate::numbers::random::SplitMix64;
use crate::scene::mesh::{LoadReport, MeshError, TetMesh};
use glam::DVec3;
use std::fmt;
use std::path::Path;

/// The scenes built into tetlab.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builtin {
    /// One regular tetrahedron, edge 1, resting on the ground.
    Tet,
    /// A unit cube of N×N×N cells, six tets per cell, resting on the ground.
    Cube,
    /// A 2 × 0.5 × 0.5 block of 4N×N×N cells held at its x = 0 end, one unit above the ground.
    Beam,
    /// A ball of radius 0.5 resting on the ground: a 2N-cell lattice cube mapped onto the ball.
    Ball,
}

impl Builtin {
    /// Every built-in scene.
    pub const ALL: [Builtin; 4] = [Builtin::Tet, Builtin::Cube, Builtin::Beam, Builtin::Ball];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Builtin::Tet => "tet",
            Builtin::Cube => "cube",
            Builtin::Beam => "beam",
            Builtin::Ball => "ball",
        }
    }

    /// The built-in scene of this name.
    pub fn from_name(name: &str) -> Option<Builtin> {
        Builtin::ALL.into_iter().find(|b| b.name() == name)
    }

    /// How many tets the scene has at `resolution`: 1 for the tet, six per lattice cell for the
    /// others (N³ cells for the cube, 4N·N·N for the beam, (2N)³ for the ball).
    ///
    /// ```
    /// use tetlab_core::scene::{Builtin, Scene};
    /// let cube = Scene::builtin(Builtin::Cube, 3).unwrap();
    /// assert_eq!(Builtin::Cube.tets(3), cube.mesh.tets.len() as u64);
    /// ```
    pub fn tets(self, resolution: u32) -> u64 {
        let n = resolution as u64;
        match self {
            Builtin::Tet => 1,
            Builtin::Cube => 6 * n * n * n,
            Builtin::Beam => 6 * 4 * n * n * n,
            Builtin::Ball => 6 * 8 * n * n * n,
        }
    }

    /// The largest resolution at which the scene has at most [`limits::MAX_TETS`] tets.
    pub(crate) fn largest_resolution(self) -> u32 {
        (limits::RESOLUTION.min..=limits::RESOLUTION.max)
            .rev()
            .find(|&n| self.tets(n) <= limits::MAX_TETS as u64)
            .unwrap_or(limits::RESOLUTION.min)
    }
}

/// A rest mesh, the particles held in place, and notes on how it was made.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// A short name: the built-in's name or the file's.
    pub name: String,
    /// The rest shape.
    pub mesh: TetMesh,
    /// Indices of pinned particles (inverse mass 0).
    pub pinned: Vec<u32>,
    /// What loading changed or noticed, one line each.
    pub notes: Vec<String>,
    /// The bodies of a scene file, which parts of the mesh are each's; empty for a scene of one
    /// body (a built-in, a mesh file), which starts at rest.
    pub bodies: Vec<SceneBody>,
}

/// Why a scene could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneError {
    /// Not a built-in name, and no file of that name.
    Unknown(String),
    /// The resolution is out of range: why.
    Resolution(String),
    /// The built-in scene would have more tets than tetlab simulates at this resolution.
    TooLarge {
        /// The scene.
        builtin: Builtin,
        /// The resolution asked for.
        resolution: u32,
    },
    /// The file could not be loaded.
    Mesh(MeshError),
    /// A mistake in a scene file: where (line and column from 1) and what.
    File {
        /// The scene file.
        path: std::path::PathBuf,
        /// Line and column, when one is to blame.
        at: Option<(usize, usize)>,
        /// What is wrong.
        message: String,
    },
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneError::Unknown(spec) => write!(
                f,
                "'{spec}' is neither a built-in scene (tet, cube, beam, ball) nor an existing file \
                 (a mesh, .node/.ele/.msh, or a scene file, .toml)"
            ),
            SceneError::Resolution(why) => f.write_str(why),
            SceneError::TooLarge {
                builtin,
                resolution,
            } => write!(
                f,
                "{} at resolution {resolution} would have {} tets, more than the {} tetlab \
                 simulates; {} goes up to resolution {}",
                builtin.name(),
                builtin.tets(*resolution),
                limits::MAX_TETS,
                builtin.name(),
                builtin.largest_resolution()
            ),
            SceneError::Mesh(e) => e.fmt(f),
            SceneError::File { path, at, message } => match at {
                Some((line, column)) => {
                    write!(f, "{}:{line}:{column}: {message}", path.display())
                }
                None => write!(f, "{}: {message}", path.display()),
            },
        }
    }
}

impl std::error::Error for SceneError {}

impl Scene {
    /// A built-in scene by name, a mesh file (`.node`, `.ele`, `.msh`) or a scene file of
    /// several bodies (`.toml`, [`Scene::load_file`]) by path.
    pub fn from_spec(spec: &str, resolution: u32) -> Result<Scene, SceneError> {
        if let Some(builtin) = Builtin::from_name(spec) {
            return Scene::builtin(builtin, resolution);
        }
        let path = Path::new(spec);
        if !crate::input::text_file::available(path) {
            return Err(SceneError::Unknown(spec.to_owned()));
        }
        if Scene::is_scene_file(spec) {
            return Scene::load_file(path);
        }
        Scene::load(path).map_err(SceneError::Mesh)
    }

    /// A built-in scene; `resolution` ([`limits::RESOLUTION`]) is the number of cells along a
    /// side (cube, beam cross-section) or half the cells across (ball), ignored by `tet`. The
    /// size is checked before anything is allocated: at most [`limits::MAX_TETS`] tets.
    pub fn builtin(builtin: Builtin, resolution: u32) -> Result<Scene, SceneError> {
        limits::RESOLUTION
            .check(resolution)
            .map_err(SceneError::Resolution)?;
        if builtin.tets(resolution) > limits::MAX_TETS as u64 {
            return Err(SceneError::TooLarge {
                builtin,
                resolution,
            });
        }
        let n = resolution as usize;
        let (mesh, pinned) = match builtin {
            Builtin::Tet => (regular_tet(), Vec::new()),
            Builtin::Cube => (
                lattice(
                    [n, n, n],
                    DVec3::new(-0.5, 0.0, -0.5),
                    DVec3::splat(1.0 / n as f64),
                ),
                Vec::new(),
            ),
            Builtin::Beam => {
                let mesh = lattice(
                    [4 * n, n, n],
                    DVec3::new(0.0, 1.0, -0.25),
                    DVec3::splat(0.5 / n as f64),
                );
                let pinned = (0..mesh.positions.len() as u32)
                    .filter(|&i| mesh.positions[i as usize].x == 0.0)
                    .collect();
                (mesh, pinned)
            }
            Builtin::Ball => (ball(2 * n), Vec::new()),
        };
        Ok(Scene {
            name: builtin.name().to_owned(),
            mesh,
            pinned,
            notes: Vec::new(),
            bodies: Vec::new(),
        })
    }

    /// A scene from a mesh file (TetGen or Gmsh, by extension).
    pub fn load(path: &Path) -> Result<Scene, MeshError> {
        let (mesh, report) = TetMesh::load(path)?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| path.display().to_string());
        Ok(Scene::from_mesh(name, mesh, report))
    }

    /// A scene from a loaded mesh. A mesh that reaches below the ground (y < 0) is lifted to rest
    /// on it; the notes say so, after what loading reported.
    pub fn from_mesh(name: String, mut mesh: TetMesh, report: LoadReport) -> Scene {
        let mut notes = report.notes();
        let lowest = mesh
            .positions
            .iter()
            .map(|p| p.y)
            .fold(f64::INFINITY, f64::min);
        if lowest < 0.0 {
            for p in &mut mesh.positions {
                p.y -= lowest;
            }
            notes.push(format!(
                "lifted by {:.4} to rest on the ground (y = 0)",
                -lowest
            ));
        }
        Scene {
            name,
            mesh,
            pinned: Vec::new(),
            notes,
            bodies: Vec::new(),
        }
    }
}

fn regular_tet() -> TetMesh {
    let r = 1.0 / 3f64.sqrt();
    let height = (2.0f64 / 3.0).sqrt();
    let positions = vec![
        DVec3::new(r, 0.0, 0.0),
        DVec3::new(-0.5 * r, 0.0, 0.5),
        DVec3::new(-0.5 * r, 0.0, -0.5),
        DVec3::new(0.0, height, 0.0),
    ];
    positively_oriented(positions, vec![[0, 1, 2, 3]])
}

/// A block of `cells` boxes of sides `size` with its low corner at `origin`, each box split into
/// six tets around its main diagonal (Kuhn's subdivision), so neighbouring cells share faces.
/// Particle (i, j, k) is number (i (ny + 1) + j)(nz + 1) + k.
pub(crate) fn lattice(cells: [usize; 3], origin: DVec3, size: DVec3) -> TetMesh {
    let [nx, ny, nz] = cells;
    let index = |i: usize, j: usize, k: usize| ((i * (ny + 1) + j) * (nz + 1) + k) as u32;
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for i in 0..=nx {
        for j in 0..=ny {
            for k in 0..=nz {
                positions.push(origin + DVec3::new(i as f64, j as f64, k as f64) * size);
            }
        }
    }
    let steps = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
    let orders = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut tets = Vec::with_capacity(nx * ny * nz * 6);
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                for order in orders {
                    let mut corner = [i, j, k];
                    let mut tet = [index(i, j, k); 4];
                    for (slot, &axis) in tet[1..].iter_mut().zip(&order) {
                        for d in 0..3 {
                            corner[d] += steps[axis][d];
                        }
                        *slot = index(corner[0], corner[1], corner[2]);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    positively_oriented(positions, tets)
}

/// A lattice cube of `cells` cells across [−1, 1]³, each point pushed radially onto the ball of
/// radius 0.5 at (0, 0.5, 0): q = p · |p|∞ / |p|₂, which maps every cube shell onto a sphere.
fn ball(cells: usize) -> TetMesh {
    let mut mesh = lattice(
        [cells; 3],
        DVec3::splat(-1.0),
        DVec3::splat(2.0 / cells as f64),
    );
    for p in &mut mesh.positions {
        let length = p.length();
        let radial = if length > 0.0 {
            *p * (p.abs().max_element() / length)
        } else {
            *p
        };
        *p = radial * 0.5 + DVec3::new(0.0, 0.5, 0.0);
    }
    mesh
}

/// Swaps two corners of every negatively oriented generated tet; generated meshes have no
/// degenerate tets, so this is all [`TetMesh::new`] would do.
fn positively_oriented(positions: Vec<DVec3>, mut tets: Vec<[u32; 4]>) -> TetMesh {
    for tet in &mut tets {
        if signed_volume(&tet.map(|i| positions[i as usize])) < 0.0 {
            tet.swap(2, 3);
        }
    }
    TetMesh { positions, tets }
}

/// A deformation of the current positions that sets up an experiment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Perturbation {
    /// Reflect vertex 0 of tet 0 through the plane of its opposite face: that tet's edge lengths
    /// stay, its volume changes sign.
    Invert,
    /// Reflect every particle through the plane x = centroid x: every tet inverted, every edge
    /// length kept.
    Mirror,
    /// Move every particle onto the plane y = (lowest y): every tet flat.
    Flatten,
    /// Displace every particle by a random vector, uniform in a cube of half-side half the mean
    /// edge length; the same seed gives the same displacements.
    Scramble(u64),
}

impl Perturbation {
    /// Parses `invert`, `mirror`, `flatten` or `scramble:SEED`.
    pub fn parse(text: &str) -> Result<Perturbation, String> {
        match text {
            "invert" => Ok(Perturbation::Invert),
            "mirror" => Ok(Perturbation::Mirror),
            "flatten" => Ok(Perturbation::Flatten),
            _ => match text.strip_prefix("scramble:") {
                Some(seed) => seed.parse().map(Perturbation::Scramble).map_err(|_| {
                    format!("'{seed}' is not a seed: expected scramble:<whole number>")
                }),
                None => Err(format!(
                    "'{text}' is not a perturbation: expected invert, mirror, flatten or scramble:SEED"
                )),
            },
        }
    }

    /// Applies the perturbation to `positions` (the current positions of `mesh`'s particles).
    pub fn apply(self, positions: &mut [DVec3], mesh: &TetMesh) {
        match self {
            Perturbation::Invert => {
                if let Some(tet) = mesh.tets.first() {
                    reflect_through_opposite_face(positions, tet, 0);
                }
            }
            Perturbation::Mirror => {
                let centroid_x =
                    positions.iter().map(|p| p.x).sum::<f64>() / positions.len().max(1) as f64;
                for p in positions.iter_mut() {
                    p.x = 2.0 * centroid_x - p.x;
                }
            }
            Perturbation::Flatten => {
                let lowest = positions.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
                for p in positions.iter_mut() {
                    p.y = lowest;
                }
            }
            Perturbation::Scramble(seed) => {
                let edges = mesh.edges();
                let mean_edge = edges
                    .iter()
                    .map(|[i, j]| mesh.positions[*i as usize].distance(mesh.positions[*j as usize]))
                    .sum::<f64>()
                    / edges.len().max(1) as f64;
                let mut rng = SplitMix64::new(seed);
                for p in positions.iter_mut() {
                    *p += rng.in_cube(0.5 * mean_edge);
                }
            }
        }
    }
}

/// Reflects corner `k` of `tet` through the plane of the other three corners: p′ = p − 2((p − a)·n)n
/// with n the unit normal of that face. The three edges at the corner keep their lengths and the
/// tet's signed volume changes sign. A face of zero area has no plane: nothing moves.
///
/// ```
/// use glam::DVec3;
/// use tetlab_core::constraints::volume::signed_volume;
/// use tetlab_core::scene::reflect_through_opposite_face;
/// let mut p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
/// reflect_through_opposite_face(&mut p, &[0, 1, 2, 3], 3);
/// assert_eq!(p[3], -DVec3::Z);
/// assert!(signed_volume(&[p[0], p[1], p[2], p[3]]) < 0.0);
/// ```
pub fn reflect_through_opposite_face(positions: &mut [DVec3], tet: &[u32; 4], k: usize) {
    let others: Vec<DVec3> = (0..4)
        .filter(|&j| j != k)
        .map(|j| positions[tet[j] as usize])
        .collect();
    let normal = (others[1] - others[0]).cross(others[2] - others[0]);
    if normal.length_squared() > 0.0 {
        let n = normal.normalize();
        let p = positions[tet[k] as usize];
        positions[tet[k] as usize] = p - 2.0 * (p - others[0]).dot(n) * n;
    }
}

impl fmt::Display for Perturbation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Perturbation::Invert => f.write_str("invert"),
            Perturbation::Mirror => f.write_str("mirror"),
            Perturbation::Flatten => f.write_str("flatten"),
            Perturbation::Scramble(seed) => write!(f, "scramble:{seed}"),
        }
    }
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `lattice`'s documentation (a unit test: the item is not exported).
    #[test]
    fn lattice_example() {
        use crate::constraints::volume::signed_volume;
        use crate::scene::lattice;
        use glam::DVec3;
        let block = lattice([2, 1, 1], DVec3::ZERO, DVec3::new(0.5, 0.1, 0.1));
        assert_eq!((block.positions.len(), block.tets.len()), (12, 12));
        // Every tet positively oriented, and together they fill the block: 1 × 0.1 × 0.1.
        let volumes: Vec<f64> = (0..12).map(|t| signed_volume(&block.corners(t))).collect();
        assert!(volumes.iter().all(|&v| v > 0.0));
        assert!((volumes.iter().sum::<f64>() - 0.01).abs() < 1e-15);
    }
}
