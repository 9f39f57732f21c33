//! A body added to a scene shown ([`Scene::with_body_dropped`]): what the workbench's "Add a
//! body" does, a scene of several bodies made without writing its file.

use super::Scene;
use super::scene_file::Placement;
use glam::{DMat3, DVec3};

impl Scene {
    /// This scene with `part` added as one more body, held over it and let go: centred over
    /// the scene's box in x and z, its lowest point half its own height above the scene's
    /// highest, at rest. A scene of one body becomes a scene of two, the first named after the
    /// scene; the new body is named after `part`, numbered where the name is taken. The pins
    /// of both come with them.
    ///
    /// ```
    /// use tetlab_core::scene::{Builtin, Scene};
    /// let cube = Scene::builtin(Builtin::Cube, 2).unwrap();
    /// let tet = Scene::builtin(Builtin::Tet, 1).unwrap();
    /// let two = cube.with_body_dropped(tet.clone());
    /// let three = two.with_body_dropped(tet);
    /// let names: Vec<&str> = three.bodies.iter().map(|b| b.name.as_str()).collect();
    /// assert_eq!(names, ["cube", "tet", "tet2"]);
    /// assert_eq!(three.mesh.positions.len(), 27 + 4 + 4);
    /// // Each new body starts above everything before it.
    /// let heights = |b: usize| -> Vec<f64> {
    ///     let r = three.bodies[b].particles.clone();
    ///     three.mesh.positions[r.start as usize..r.end as usize].iter().map(|p| p.y).collect()
    /// };
    /// let highest_before = heights(1).into_iter().fold(f64::MIN, f64::max);
    /// assert!(heights(2).into_iter().all(|y| y > highest_before));
    /// ```
    pub fn with_body_dropped(&self, part: Scene) -> Scene {
        let mut scene = if self.bodies.is_empty() {
            let mut whole = Scene {
                name: self.name.clone(),
                mesh: super::mesh::TetMesh {
                    positions: Vec::new(),
                    tets: Vec::new(),
                },
                pinned: Vec::new(),
                notes: Vec::new(),
                bodies: Vec::new(),
            };
            let keep = Placement {
                scale: DMat3::IDENTITY,
                bend: None,
                rotation: DMat3::IDENTITY,
                translate: DVec3::ZERO,
            };
            whole.add(self.name.clone(), self.clone(), keep, DVec3::ZERO);
            whole
        } else {
            self.clone()
        };
        let (low, high) = super::mesh::bounds(&scene.mesh.positions);
        let (part_low, part_high) = super::mesh::bounds(&part.mesh.positions);
        let part_centre = 0.5 * (part_low + part_high);
        let over = 0.5 * (low + high);
        let lift = high.y + 0.5 * (part_high.y - part_low.y) - part_low.y;
        let translate = DVec3::new(over.x - part_centre.x, lift, over.z - part_centre.z);
        let base = part.name.clone();
        let name = (1..)
            .map(|k| {
                if k == 1 {
                    base.clone()
                } else {
                    format!("{base}{k}")
                }
            })
            .find(|name| scene.bodies.iter().all(|b| &b.name != name))
            .expect("some number is free");
        let placement = Placement {
            scale: DMat3::IDENTITY,
            bend: None,
            rotation: DMat3::IDENTITY,
            translate,
        };
        scene.add(name, part, placement, DVec3::ZERO);
        scene
    }
}
