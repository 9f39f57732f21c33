//! Which entities of a recording are each body's ([`BodyPart`]): a scene of several bodies is
//! logged body by body, so that the viewer lists each under its own entity, shows or hides it,
//! and plots its metrics and energy beside the others'; a scene of one body is one part.

use std::ops::Range;
use tetlab_core::scene::Scene;
use tetlab_core::simulation::Simulation;
use tetlab_core::teaching::visual;

/// One body as a recording logs it: where (`world/` for a scene of one body, or
/// `world/bodies/<name>/` and `bodies/<name>/` for one of several) and what of the scene's mesh
/// is its own, numbered from its first particle.
#[derive(Clone, Debug)]
pub struct BodyPart {
    /// Where its mesh and edges go: `world/`, or `world/bodies/<name>/`.
    pub world: String,
    /// Where its metrics and energy go (`bodies/<name>/`); `None` for a scene of one body,
    /// whose metrics are the scene's.
    pub plots: Option<String>,
    /// Its particles in the scene's numbering.
    pub particles: Range<usize>,
    /// The faces drawn ([`visual::display_faces`]) whose corners are its, numbered from its
    /// first particle.
    pub faces: Vec<[u32; 3]>,
    /// The edges drawn ([`visual::display_edges`]) as strips ([`visual::edge_strips`]), numbered
    /// from its first particle.
    pub strips: Vec<Vec<u32>>,
}

impl BodyPart {
    /// The parts of `simulation` of `scene`: one per body of a scene file, or the whole mesh.
    /// A body's name is one entity path part, escaped where it holds a `/` or a space.
    ///
    /// Every face and edge drawn is in exactly one part: the bodies share no particle.
    pub fn of(scene: &Scene, simulation: &Simulation) -> Vec<BodyPart> {
        let faces = visual::display_faces(&scene.mesh);
        let edges = visual::display_edges(&scene.mesh);
        let whole = 0..simulation.positions().len() as u32;
        let bodies: Vec<(Option<String>, Range<u32>)> = if simulation.bodies().is_empty() {
            vec![(None, whole)]
        } else {
            (simulation.bodies().iter())
                .map(|b| (Some(path_part(&b.name)), b.particles.clone()))
                .collect()
        };
        bodies
            .into_iter()
            .map(|(name, range)| {
                let start = range.start;
                let own = |v: &u32| range.contains(v);
                let faces: Vec<[u32; 3]> = (faces.iter())
                    .filter(|f| f.iter().all(own))
                    .map(|f| f.map(|v| v - start))
                    .collect();
                let edges: Vec<[u32; 2]> = (edges.iter())
                    .filter(|e| e.iter().all(own))
                    .map(|e| e.map(|v| v - start))
                    .collect();
                BodyPart {
                    world: name
                        .as_ref()
                        .map_or("world/".to_owned(), |n| format!("world/bodies/{n}/")),
                    plots: name.map(|n| plots(&n)),
                    particles: range.start as usize..range.end as usize,
                    faces,
                    strips: visual::edge_strips(&edges),
                }
            })
            .collect()
    }
}

/// Where each body's metrics and energy go, `bodies/<name>/` (none for a scene of one body):
/// what the layout plots beside the scene's.
pub fn body_plots(simulation: &Simulation) -> Vec<String> {
    (simulation.bodies().iter())
        .map(|b| plots(&path_part(&b.name)))
        .collect()
}

/// `bodies/<part>/`.
fn plots(part: &str) -> String {
    format!("bodies/{part}/")
}

/// A body's name as one entity path part, escaped where it holds a `/` or a space.
fn path_part(name: &str) -> String {
    rerun::EntityPathPart::new(name).escaped_string()
}
