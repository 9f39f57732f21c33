//! The 3D view as a widget: camera input, picking and dragging particles, and the paint
//! callback that draws [`geometry::build`]'s output with the [`super::render`] renderer.
//!
//! Left-drag on a particle moves it (through the grab constraint while playing, directly while
//! paused); left-drag elsewhere orbits, right- or middle-drag pans, the wheel zooms, a click
//! selects a particle and its tet.

use super::camera::OrbitCamera;
use super::geometry::{self, SceneCache, ViewGeometry, ViewOptions};
use super::render::ViewCallback;
use super::workbench::Workbench;
use eframe::egui::{self, PointerButton, Pos2, Rect, Sense, Vec2};
use eframe::egui_wgpu;
use glam::{DVec3, Vec2 as GVec2, Vec3};

/// How close (points) the pointer must be to a particle to pick it.
const PICK_RADIUS: f32 = 12.0;

/// The state of the 3D view between frames.
pub struct Viewport {
    /// The camera.
    pub camera: OrbitCamera,
    /// The particle under the pointer.
    pub hovered: Option<usize>,
    /// The plane a dragged particle moves in: a point on it and its unit normal.
    drag_plane: Option<(Vec3, Vec3)>,
    /// Where the view was drawn last, in points.
    pub rect: Rect,
    /// Which of the renderer's views this is: 0 the main one, 1 the comparison.
    pub view: usize,
    /// A camera change that waits for the view's size: frame the body, or reset the camera.
    pending: Option<CameraChange>,
    /// What the view draws, kept between frames (the paint callback reads it).
    geometry: std::sync::Arc<std::sync::Mutex<ViewGeometry>>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum CameraChange {
    Frame,
    Reset,
}

impl Default for Viewport {
    /// A view that frames the rest body when first drawn.
    fn default() -> Self {
        Viewport {
            camera: OrbitCamera::default(),
            hovered: None,
            drag_plane: None,
            rect: Rect::NOTHING,
            view: 0,
            pending: Some(CameraChange::Reset),
            geometry: Default::default(),
        }
    }
}

impl Viewport {
    /// Keeps the camera angles and frames the current body, when the view is next drawn (at its
    /// size then).
    pub fn frame(&mut self) {
        self.pending = Some(CameraChange::Frame);
    }

    /// Back to the first view, when the view is next drawn: the default angles, framing the rest
    /// shape.
    pub fn reset_camera(&mut self) {
        self.pending = Some(CameraChange::Reset);
    }

    /// Applies a pending camera change for a view of the size of `self.rect`.
    fn apply_camera_change(&mut self, bench: &Workbench) {
        let Some(change) = self.pending.take() else {
            return;
        };
        let aspect = self.rect.width() / self.rect.height().max(1.0);
        let positions = match change {
            CameraChange::Frame => bench.simulation.positions(),
            CameraChange::Reset => bench.simulation.rest_positions(),
        };
        let (lo, hi) = tetlab_core::scene::mesh::bounds(positions);
        if change == CameraChange::Reset {
            self.camera = OrbitCamera::default();
        }
        self.camera.frame(lo.as_vec3(), hi.as_vec3(), aspect);
    }

    /// Shows the view in all the space `ui` has left.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        bench: &mut Workbench,
        cache: &SceneCache,
        options: &ViewOptions,
    ) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        self.rect = rect;
        self.apply_camera_change(bench);
        let aspect = rect.width() / rect.height().max(1.0);
        let pointer = response.hover_pos();
        self.hovered = pointer.and_then(|p| self.pick(bench, rect, p));

        if response.drag_started_by(PointerButton::Primary) {
            let start = ui.input(|i| i.pointer.press_origin()).or(pointer);
            if let Some(particle) = start.and_then(|p| self.pick(bench, rect, p)) {
                let position = bench.simulation.positions()[particle].as_vec3();
                self.drag_plane = Some((position, self.camera.forward()));
                bench.start_drag(particle, position.as_dvec3());
            }
        }
        if response.dragged_by(PointerButton::Primary) {
            match (self.drag_plane, pointer) {
                (Some(plane), Some(p)) => {
                    if let Some(target) = self.on_plane(rect, aspect, p, plane) {
                        bench.drag_to(target.as_dvec3());
                    }
                }
                (None, _) => self.camera.orbit(to_glam(response.drag_delta())),
                _ => {}
            }
        }
        if response.drag_stopped() && self.drag_plane.take().is_some() {
            bench.end_drag();
        }
        if response.dragged_by(PointerButton::Secondary)
            || response.dragged_by(PointerButton::Middle)
        {
            self.camera
                .pan(to_glam(response.drag_delta()), rect.height());
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.camera.zoom(scroll / 50.0);
            }
        }
        if response.clicked()
            && let Some(particle) = self.hovered
        {
            bench.select_particle(particle);
        }

        geometry::update(
            &mut self.geometry.lock().unwrap_or_else(|e| e.into_inner()),
            bench,
            cache,
            options,
            self.hovered,
        );
        let background = if ui.visuals().dark_mode {
            [0.09, 0.10, 0.12, 1.0]
        } else {
            [0.93, 0.94, 0.96, 1.0]
        };
        let callback = ViewCallback {
            view: self.view,
            geometry: std::sync::Arc::clone(&self.geometry),
            view_projection: self.camera.view_projection(aspect),
            light: (self.camera.eye() - self.camera.target + Vec3::Y * self.camera.distance)
                .normalize(),
            size_points: [rect.width(), rect.height()],
            background,
        };
        ui.painter()
            .add(egui_wgpu::Callback::new_paint_callback(rect, callback));
        legend(ui, rect, bench, options);
    }

    /// The particle nearest to screen point `p` within [`PICK_RADIUS`], in front of the camera.
    fn pick(&self, bench: &Workbench, rect: Rect, p: Pos2) -> Option<usize> {
        let mut best: Option<(usize, f32)> = None;
        for (i, position) in bench.simulation.positions().iter().enumerate() {
            let Some((screen, depth)) = project(&self.camera, rect, *position) else {
                continue;
            };
            let distance = screen.distance(p);
            // Nearer to the pointer wins; at equal distance on screen, nearer to the eye.
            let score = distance + depth * 1e-3;
            if distance <= PICK_RADIUS && best.is_none_or(|(_, s)| score < s) {
                best = Some((i, score));
            }
        }
        best.map(|(i, _)| i)
    }

    /// Where the ray under screen point `p` meets `plane` (a point on it, its normal).
    fn on_plane(
        &self,
        rect: Rect,
        aspect: f32,
        p: Pos2,
        (point, normal): (Vec3, Vec3),
    ) -> Option<Vec3> {
        let ndc = GVec2::new(
            (p.x - rect.min.x) / rect.width() * 2.0 - 1.0,
            1.0 - (p.y - rect.min.y) / rect.height() * 2.0,
        );
        let (origin, direction) = self.camera.ray(ndc, aspect);
        let denominator = direction.dot(normal);
        if denominator.abs() < 1e-6 {
            return None;
        }
        let t = (point - origin).dot(normal) / denominator;
        (t > 0.0).then(|| origin + direction * t)
    }
}

fn to_glam(v: Vec2) -> GVec2 {
    GVec2::new(v.x, v.y)
}

/// The colour key in the view's corner.
fn legend(ui: &egui::Ui, rect: Rect, bench: &Workbench, options: &ViewOptions) {
    use tetlab_core::teaching::visual;
    let painter = ui.painter_at(rect);
    let mut y = rect.min.y + 10.0;
    let font = egui::FontId::proportional(13.0);
    let text = ui.visuals().text_color();
    let mut entry = |colour: visual::Rgba, label: String| {
        let swatch = Rect::from_min_size(
            Pos2::new(rect.min.x + 10.0, y + 2.0),
            egui::vec2(12.0, 12.0),
        );
        painter.rect_filled(
            swatch,
            2.0,
            egui::Color32::from_rgba_unmultiplied(colour[0], colour[1], colour[2], colour[3]),
        );
        painter.text(
            Pos2::new(rect.min.x + 28.0, y),
            egui::Align2::LEFT_TOP,
            label,
            font.clone(),
            text,
        );
        y += 18.0;
    };
    entry(
        visual::INVERTED,
        format!("inverted ({} tets)", bench.metrics.inverted_tets),
    );
    entry(geometry::SELECTED, "selected tet".to_owned());
    let stepping = bench
        .stepping
        .is_some_and(|s| s.pending(&bench.simulation).is_some());
    if stepping {
        entry(geometry::PENDING, "next projection".to_owned());
    }
    let active = *bench.simulation.active();
    let families = bench.simulation.families();
    for family in families.all().filter(|&f| options.arrows && active.get(f)) {
        for quantity in visual::Quantity::of_family(families, family) {
            entry(quantity.colour(families), quantity.label(families));
        }
    }
    if stepping {
        entry(
            visual::CORRECTION,
            format!("dx of the next projection (x{})", options.correction_gain),
        );
    } else if options.corrections {
        entry(
            visual::CORRECTION,
            format!("dp, last substep (x{})", options.correction_gain),
        );
    }
    if bench.mode_shown.is_some() {
        entry(
            visual::MODE,
            "mode of the energy (arrows; the tet moved along it)".to_owned(),
        );
    }
}

/// Where world point `p` appears in a view drawn in `rect`, and its depth (0 near, 1 far); `None`
/// behind the camera.
pub fn project(camera: &OrbitCamera, rect: Rect, p: DVec3) -> Option<(Pos2, f32)> {
    let clip =
        camera.view_projection(rect.width() / rect.height().max(1.0)) * p.as_vec3().extend(1.0);
    if clip.w <= 0.0 {
        return None;
    }
    let ndc = clip.truncate() / clip.w;
    let screen = Pos2::new(
        rect.min.x + (ndc.x + 1.0) * 0.5 * rect.width(),
        rect.min.y + (1.0 - ndc.y) * 0.5 * rect.height(),
    );
    Some((screen, ndc.z))
}
