//! What the 3D view draws, as triangles and lines, with the colours and arrows of
//! `tetlab_core::teaching::visual` (the same the recorder logs). The view keeps them between frames
//! ([`ViewGeometry`]) and brings them up to date only when something it shows changed: a frame
//! played, an edit, the selection, the pointer, the options. A paused view builds and uploads
//! nothing.

use super::vertices::{Geometry, Vertex};
use super::workbench::{ModeShown, Workbench};
use glam::{DVec3, Vec3};
use tetlab_core::constraints::volume::signed_volume;
use tetlab_core::scene::mesh::TetMesh;
use tetlab_core::teaching::visual::{self, Arrow, Rgba};

/// Display options of the 3D view.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct ViewOptions {
    /// Draw every tet face, translucent, instead of the outer surface.
    pub see_through: bool,
    /// Colour faces by V/V₀ instead of inverted/healthy.
    pub colour_by_volume: bool,
    /// Draw particles as handles.
    pub particles: bool,
    /// Draw edges.
    pub edges: bool,
    /// Draw the gradient arrows of the selected tet.
    pub arrows: bool,
    /// Draw arrows on every tet (small meshes only).
    pub arrows_on_all_tets: bool,
    /// Arrow length factor.
    pub arrow_scale: f32,
    /// Draw Δp, the correction of the last substep, at the particles that have gradient arrows.
    pub corrections: bool,
    /// How many times its true length Δp is drawn.
    pub correction_gain: f32,
}

impl Default for ViewOptions {
    fn default() -> Self {
        Self {
            see_through: false,
            colour_by_volume: false,
            particles: true,
            edges: true,
            arrows: true,
            arrows_on_all_tets: false,
            arrow_scale: 1.0,
            corrections: true,
            correction_gain: 1.0,
        }
    }
}

/// Above this many tets a scene is shown as a body: particle handles and arrows start off
/// (the armadillo's 1180 handles, each an octahedron, hide its surface; the bunny's 333 do not).
pub const BIG_MESH_TETS: usize = 2000;

impl ViewOptions {
    /// The default options for a scene of `tets` tets: [`ViewOptions::default`], with particle
    /// handles and every arrow off above [`BIG_MESH_TETS`].
    pub fn for_size(tets: usize) -> Self {
        let mut options = ViewOptions::default();
        options.fit_size(tets);
        options
    }

    /// Turns particle handles and arrows on for a scene of `tets` tets, or off above
    /// [`BIG_MESH_TETS`]; the other options stay as they are.
    pub fn fit_size(&mut self, tets: usize) {
        let small = tets <= BIG_MESH_TETS;
        self.particles = small;
        self.arrows = small;
        self.corrections = small;
    }
}

/// Meshes with at most this many tets may show arrows on every tet.
pub const ARROWS_ON_ALL_UP_TO: usize = 64;

/// Selected tets and particles.
pub const SELECTED: Rgba = [250, 200, 40, 255];
/// The constraint step-by-step mode projects next, and the selected contact: its particles and
/// the lines between them.
pub const PENDING: Rgba = [40, 220, 220, 255];
/// The particle under the pointer.
const HOVERED: Rgba = [255, 255, 255, 255];
/// Pinned particles.
const PINNED: Rgba = [40, 40, 40, 255];
/// The ground grid.
const GRID: Rgba = [120, 120, 120, 255];

/// Per-scene data the view reuses every frame: which faces and edges to draw.
pub struct SceneCache {
    surface_faces: Vec<([u32; 3], u32)>,
    all_faces: Vec<([u32; 3], u32)>,
    display_edges: Vec<[u32; 2]>,
    all_edges: Vec<[u32; 2]>,
    /// The size of the rest body (bounding-box diagonal).
    pub size: f64,
}

impl SceneCache {
    /// The faces and edges of `mesh`.
    pub fn new(mesh: &TetMesh) -> Self {
        Self {
            surface_faces: visual::faces_with_tets(
                mesh,
                mesh.tets.len() <= visual::ALL_FACES_UP_TO,
            ),
            all_faces: visual::faces_with_tets(mesh, true),
            display_edges: visual::display_edges(mesh),
            all_edges: mesh.edges(),
            size: visual::body_size(&mesh.positions),
        }
    }
}

/// What the view draws, kept between frames: the vertices, and what they were built from, so
/// that they are built again (and uploaded again) only when that changes.
pub struct ViewGeometry {
    geometry: Geometry,
    built_from: Option<Key>,
    /// Which view geometry this is, among all made (the renderer keeps what it uploaded per
    /// view, and a view may be given another geometry).
    id: u64,
    generation: u64,
    scratch: Scratch,
}

impl Default for ViewGeometry {
    fn default() -> Self {
        static MADE: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        ViewGeometry {
            geometry: Geometry::default(),
            built_from: None,
            id: MADE.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            generation: 0,
            scratch: Scratch::default(),
        }
    }
}

/// Buffers reused from frame to frame.
#[derive(Default)]
struct Scratch {
    inverted: Vec<bool>,
    colours: Vec<Rgba>,
    arrows: Vec<Arrow>,
}

/// Everything the geometry is built from, but the positions (whose change a new revision of the
/// workbench says).
#[derive(Clone, Copy, PartialEq)]
struct Key {
    revision: u64,
    selected_tet: Option<usize>,
    selected_particle: Option<usize>,
    dragging: Option<usize>,
    hovered: Option<usize>,
    options: ViewOptions,
    stepping: bool,
    mode: Option<ModeShown>,
}

impl ViewGeometry {
    /// The vertices.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// This geometry and its version: the version grows by one whenever the vertices are built
    /// again. What the renderer compares to know whether to upload.
    pub fn version(&self) -> (u64, u64) {
        (self.id, self.generation)
    }

    /// Every vertex buffer, as the bytes uploaded to the GPU.
    pub fn buffers(&self) -> [&[u8]; 5] {
        let g = &self.geometry;
        [
            &g.triangles,
            &g.transparent,
            &g.lines,
            &g.overlay_triangles,
            &g.overlay_lines,
        ]
        .map(|v| bytemuck::cast_slice(v.as_slice()))
    }

    /// How many vertices it holds.
    pub fn vertices(&self) -> usize {
        let g = &self.geometry;
        g.triangles.len()
            + g.transparent.len()
            + g.lines.len()
            + g.overlay_triangles.len()
            + g.overlay_lines.len()
    }
}

/// Builds everything the view draws, as a new [`Geometry`] (for tests; the view keeps its own
/// with [`update`]).
pub fn build(
    bench: &Workbench,
    cache: &SceneCache,
    options: &ViewOptions,
    hovered: Option<usize>,
) -> Geometry {
    let mut view = ViewGeometry::default();
    update(&mut view, bench, cache, options, hovered);
    view.geometry
}

/// Brings what the view draws up to date, in place: nothing is done when nothing it shows
/// changed since the last call. Allocates nothing once the buffers have grown to the scene.
pub fn update(
    view: &mut ViewGeometry,
    bench: &Workbench,
    cache: &SceneCache,
    options: &ViewOptions,
    hovered: Option<usize>,
) {
    let key = Key {
        revision: bench.revision(),
        selected_tet: bench.selected_tet,
        selected_particle: bench.selected_particle,
        dragging: bench.dragging,
        hovered,
        options: *options,
        stepping: bench.stepping.is_some(),
        mode: bench.mode_shown,
    };
    if view.built_from == Some(key) {
        return;
    }
    view.built_from = Some(key);
    view.generation += 1;
    let geometry = &mut view.geometry;
    for list in [
        &mut geometry.triangles,
        &mut geometry.transparent,
        &mut geometry.lines,
        &mut geometry.overlay_triangles,
        &mut geometry.overlay_lines,
    ] {
        list.clear();
    }
    let scratch = &mut view.scratch;
    let simulation = &bench.simulation;
    let positions = simulation.positions();
    let tets = simulation.tets();

    let (faces, alpha) = if options.see_through {
        (&cache.all_faces, 90)
    } else {
        (&cache.surface_faces, 255)
    };
    for &(face, tet) in faces {
        let tet = tet as usize;
        let inverted = signed_volume(&tets[tet].map(|i| positions[i as usize])) < 0.0;
        // Inverted wins over everything, the selection included (its edges are outlined instead).
        let mut colour = if inverted {
            visual::INVERTED
        } else if bench.selected_tet == Some(tet) {
            SELECTED
        } else if options.colour_by_volume {
            let rest = simulation.rest_volume(tet);
            let ratio = if rest > 0.0 {
                signed_volume(&tets[tet].map(|i| positions[i as usize])) / rest
            } else {
                1.0
            };
            visual::volume_ratio_colour(ratio)
        } else {
            visual::HEALTHY
        };
        colour[3] = alpha;
        let target = if alpha < 255 {
            &mut geometry.transparent
        } else {
            &mut geometry.triangles
        };
        triangle(
            target,
            face.map(|i| positions[i as usize].as_vec3()),
            colour,
        );
    }

    if options.edges {
        let edges = if options.see_through {
            &cache.all_edges
        } else {
            &cache.display_edges
        };
        for &[a, b] in edges {
            line(
                &mut geometry.lines,
                positions[a as usize].as_vec3(),
                positions[b as usize].as_vec3(),
                visual::EDGE,
            );
        }
    }
    if let Some(tet) = bench.selected_tet {
        let corners = tets[tet];
        for (a, b) in tetlab_core::scene::mesh::TET_EDGES {
            line(
                &mut geometry.lines,
                positions[corners[a] as usize].as_vec3(),
                positions[corners[b] as usize].as_vec3(),
                SELECTED,
            );
        }
    }

    if options.particles {
        visual::inverted_tets(positions, tets, &mut scratch.inverted);
        let colours = &mut scratch.colours;
        visual::particle_colours(positions.len(), tets, &scratch.inverted, colours);
        visual::held_particle_colours(simulation, colours);
        let radius = (0.012 * cache.size) as f32;
        for (i, p) in positions.iter().enumerate() {
            let colour = if hovered == Some(i) {
                HOVERED
            } else if bench.selected_particle == Some(i) || bench.dragging == Some(i) {
                SELECTED
            } else if simulation.is_pinned(i) {
                PINNED
            } else {
                colours[i]
            };
            octahedron(&mut geometry.triangles, p.as_vec3(), radius, colour);
        }
    }

    if simulation.settings().ground {
        ground_grid(&mut geometry.lines, simulation.rest_positions(), cache.size);
    }

    let arrows = &mut scratch.arrows;
    arrows.clear();
    let pending = bench.stepping.and_then(|s| s.pending(simulation));
    let radius = (0.02 * cache.size) as f32;
    if let Some(projection) = &pending {
        outline(geometry, positions, projection.particles(), radius);
        visual::projection_arrows(
            simulation.families(),
            positions,
            projection,
            options.arrow_scale as f64,
            options.correction_gain as f64,
            arrows,
        );
    } else {
        tet_arrows(bench, options, arrows);
        if options.arrows {
            visual::contact_arrows(simulation, options.arrow_scale as f64, arrows);
            if let Some(particle) = bench.selected_particle {
                if let Some(&pair) = simulation.contacts_of(particle).first() {
                    let pair = simulation.contact_pairs()[pair];
                    outline(geometry, positions, &pair, radius);
                }
                visual::selected_contact_arrows(
                    simulation,
                    particle,
                    options.arrow_scale as f64,
                    options.correction_gain as f64,
                    arrows,
                );
            }
        }
    }
    if let Some(mode) = bench.mode_shown.filter(|m| m.tet < tets.len()) {
        let corners = tets[mode.tet];
        let moved = visual::along_mode(positions, corners, &mode.vector, mode.offset);
        for (a, b) in tetlab_core::scene::mesh::TET_EDGES {
            line(
                &mut geometry.overlay_lines,
                moved[a].as_vec3(),
                moved[b].as_vec3(),
                visual::MODE,
            );
        }
        visual::mode_arrows(
            positions,
            corners,
            &mode.vector,
            options.arrow_scale as f64,
            arrows,
        );
    }
    for arrow in arrows.iter() {
        draw_arrow(
            geometry,
            arrow.quantity.colour(simulation.families()),
            arrow,
        );
    }
}

/// The particles of one constraint (the projection step-by-step mode makes next, the selected
/// contact) outlined: a line between every two of them and a marker on each.
fn outline(geometry: &mut Geometry, positions: &[DVec3], particles: &[u32], radius: f32) {
    for a in 0..particles.len() {
        for b in a + 1..particles.len() {
            line(
                &mut geometry.lines,
                positions[particles[a] as usize].as_vec3(),
                positions[particles[b] as usize].as_vec3(),
                PENDING,
            );
        }
    }
    for &i in particles {
        let at = positions[i as usize].as_vec3();
        octahedron(&mut geometry.triangles, at, radius, PENDING);
    }
}

/// The arrows of the selected tet (or of every tet of a small mesh): ∇C per active family, and
/// Δp of the last substep, as the options ask ([`visual::selected_arrows`], as recorded).
fn tet_arrows(bench: &Workbench, options: &ViewOptions, arrows: &mut Vec<Arrow>) {
    let simulation = &bench.simulation;
    let all = options.arrows_on_all_tets && simulation.tets().len() <= ARROWS_ON_ALL_UP_TO;
    let selection = match (all, bench.selected_tet) {
        (true, _) => visual::ArrowSelection::AllTets,
        (false, Some(tet)) => visual::ArrowSelection::Tet(tet),
        (false, None) => visual::ArrowSelection::None,
    };
    visual::selected_arrows(
        simulation,
        selection,
        options.arrows.then_some(options.arrow_scale as f64),
        options
            .corrections
            .then_some(options.correction_gain as f64),
        arrows,
    );
}

fn vertex(position: Vec3, normal: Vec3, color: Rgba) -> Vertex {
    Vertex {
        position: position.to_array(),
        normal: normal.to_array(),
        color,
    }
}

fn triangle(out: &mut Vec<Vertex>, [a, b, c]: [Vec3; 3], colour: Rgba) {
    let normal = (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::Y);
    out.extend([a, b, c].map(|p| vertex(p, normal, colour)));
}

fn line(out: &mut Vec<Vertex>, a: Vec3, b: Vec3, colour: Rgba) {
    out.extend([vertex(a, Vec3::Y, colour), vertex(b, Vec3::Y, colour)]);
}

/// A particle handle: a small octahedron.
fn octahedron(out: &mut Vec<Vertex>, centre: Vec3, r: f32, colour: Rgba) {
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    for sx in [-1.0f32, 1.0] {
        for sy in [-1.0f32, 1.0] {
            for sz in [-1.0f32, 1.0] {
                let (a, b, c) = (axes[0] * sx * r, axes[1] * sy * r, axes[2] * sz * r);
                let corners = if sx * sy * sz > 0.0 {
                    [a, b, c]
                } else {
                    [a, c, b]
                };
                triangle(out, corners.map(|v| centre + v), colour);
            }
        }
    }
}

/// An arrow: a shaft from the particle along its vector and a cone at its tip, in its quantity's
/// colour, in the overlay (never hidden by the body).
fn draw_arrow(geometry: &mut Geometry, colour: Rgba, arrow: &Arrow) {
    let start = arrow.origin.as_vec3();
    let vector = arrow.vector.as_vec3();
    let length = vector.length();
    if length <= 0.0 || !length.is_finite() {
        return;
    }
    let tip = start + vector;
    line(&mut geometry.overlay_lines, start, tip, colour);
    let direction = vector / length;
    let head = 0.2 * length;
    let base = tip - direction * head;
    let side = direction.any_orthonormal_vector() * (0.35 * head);
    let other = direction.cross(side);
    let segments = 8;
    for k in 0..segments {
        let angle = |k: usize| std::f32::consts::TAU * k as f32 / segments as f32;
        let ring = |a: f32| base + side * a.cos() + other * a.sin();
        let (p, q) = (ring(angle(k)), ring(angle(k + 1)));
        triangle(&mut geometry.overlay_triangles, [tip, p, q], colour);
        triangle(&mut geometry.overlay_triangles, [base, q, p], colour);
    }
}

/// Grid lines on y = 0 around the rest body, 20 cells across three times its size.
fn ground_grid(out: &mut Vec<Vertex>, rest: &[DVec3], size: f64) {
    let (lo, hi) = tetlab_core::scene::mesh::bounds(rest);
    let centre = (lo + hi) * 0.5;
    let half = 1.5 * size;
    let cells = 20;
    for k in 0..=cells {
        let t = -half + 2.0 * half * k as f64 / cells as f64;
        let x = (centre.x + t) as f32;
        let z = (centre.z + t) as f32;
        let (x0, x1) = ((centre.x - half) as f32, (centre.x + half) as f32);
        let (z0, z1) = ((centre.z - half) as f32, (centre.z + half) as f32);
        line(out, Vec3::new(x, 0.0, z0), Vec3::new(x, 0.0, z1), GRID);
        line(out, Vec3::new(x0, 0.0, z), Vec3::new(x1, 0.0, z), GRID);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tetlab_core::scene::Builtin;
    use tetlab_core::simulation::Settings;

    #[test]
    fn an_inverted_selected_tet_gets_arrows_and_the_geometry_is_well_formed() {
        let mut bench = Workbench::builtin(Builtin::Tet, 1, Settings::default());
        bench.invert_selected();
        let cache = SceneCache::new(&bench.scene.mesh);
        let geometry = build(&bench, &cache, &ViewOptions::default(), None);
        assert_eq!(geometry.triangles.len() % 3, 0);
        assert_eq!(geometry.lines.len() % 2, 0);
        let arrow_colour = visual::family_colour(
            bench.simulation.families(),
            tetlab_core::constraints::Family::VOLUME,
        );
        assert!(
            geometry
                .overlay_lines
                .iter()
                .any(|v| v.color == arrow_colour),
            "volume arrows are drawn"
        );
        assert!(
            geometry
                .triangles
                .iter()
                .chain(&geometry.lines)
                .all(|v| v.position.iter().all(|x| x.is_finite()))
        );
    }

    /// The view keeps its vertices while nothing it shows changes (no upload then), and builds
    /// them again after a step, a selection or an option changes.
    #[test]
    fn the_view_is_built_again_only_when_what_it_shows_changes() {
        let mut bench = Workbench::builtin(Builtin::Cube, 2, Settings::default());
        let cache = SceneCache::new(&bench.scene.mesh);
        let mut options = ViewOptions::default();
        let mut view = ViewGeometry::default();
        update(&mut view, &bench, &cache, &options, None);
        let first = view.version();
        update(&mut view, &bench, &cache, &options, None);
        assert_eq!(view.version(), first, "nothing changed: kept");

        bench.set_playing(true);
        bench.step_frame();
        update(&mut view, &bench, &cache, &options, None);
        let stepped = view.version();
        assert_ne!(stepped, first, "the particles moved");
        update(&mut view, &bench, &cache, &options, None);
        assert_eq!(view.version(), stepped);

        options.edges = false;
        update(&mut view, &bench, &cache, &options, None);
        let edges_off = view.version();
        assert_ne!(edges_off, stepped, "an option changed");
        update(&mut view, &bench, &cache, &options, Some(0));
        assert_ne!(view.version(), edges_off, "the hovered particle changed");
    }

    /// Above [`BIG_MESH_TETS`] the body is drawn without particle handles and arrows (its
    /// surface, edges and inverted tets only); at or below it, with them.
    #[test]
    fn a_big_mesh_is_drawn_as_a_body() {
        let small = ViewOptions::for_size(BIG_MESH_TETS);
        assert!(small.particles && small.arrows && small.corrections);
        let big = ViewOptions::for_size(BIG_MESH_TETS + 1);
        assert!(!big.particles && !big.arrows && !big.corrections);
        assert!(big.edges, "the other options stay");

        let mut bench = Workbench::builtin(Builtin::Cube, 2, Settings::default());
        bench.invert_selected();
        let cache = SceneCache::new(&bench.scene.mesh);
        let with_handles = build(&bench, &cache, &small, None);
        assert!(!with_handles.overlay_lines.is_empty(), "arrows drawn");
        let as_a_body = build(&bench, &cache, &big, None);
        assert!(as_a_body.overlay_lines.is_empty(), "no arrows");
        assert!(as_a_body.overlay_triangles.is_empty(), "no arrow heads");
        let handles = bench.simulation.positions().len() * 8 * 3;
        assert_eq!(
            with_handles.triangles.len() - as_a_body.triangles.len(),
            handles,
            "one octahedron per particle, and only those, left out"
        );
    }

    #[test]
    fn see_through_draws_every_face_translucent() {
        let bench = Workbench::builtin(Builtin::Cube, 2, Settings::default());
        let cache = SceneCache::new(&bench.scene.mesh);
        let options = ViewOptions {
            see_through: true,
            ..ViewOptions::default()
        };
        let geometry = build(&bench, &cache, &options, None);
        assert_eq!(geometry.transparent.len(), 48 * 4 * 3);
    }
}
