//! What a simulation looks like in a recording: the entities [`Recorder`] logs, static data once
//! and what changes every frame, all derived from [`tetlab_core::teaching::visual`] like the workbench's
//! view.

use super::body_parts::BodyPart;
use glam::Vec3;
use rerun::RecordingStream;
use tetlab_core::constraints::Families;
use tetlab_core::energy::modes::Modes;
use tetlab_core::measures::energy_account::Energy;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::Scene;
use tetlab_core::simulation::Simulation;
use tetlab_core::teaching::visual::{self, Arrow, Quantity, Rgba};

/// Which gradient arrows to log.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ArrowsMode {
    /// None.
    None,
    /// Those of the tet given by --tet.
    Selected,
    /// Those of every tet.
    All,
}

/// Logs a simulation to a recording: static data once, what changes every frame.
///
/// Entities, under a root (empty, or e.g. `compare/` for a second simulation): `world` (view
/// coordinates, y up; the viewer draws its grid on y = 0, the ground), `world/particles`,
/// `world/mesh` and `world/edges` (all faces and edges of a small mesh, the surface of a large
/// one, as [`visual::display_faces`] and [`visual::display_edges`] choose; for a scene of
/// several bodies, each body's under `world/bodies/<name>/mesh` and `…/edges` instead, and its
/// metrics and energy under `bodies/<name>/metrics/<name>` and `bodies/<name>/energy/<part>`,
/// [`BodyPart`]),
/// `constraints/<family>` (a constraint file's text, for each in use),
/// `world/gradients/<family>` (and, for a constraint file that gives its own gradient,
/// `world/gradients/<family>-yours` where it differs from AD's, or `-ad` where the file's is
/// used), `world/corrections` (Δp of the last substep, at its true length),
/// `metrics/<name>`; with [`Recorder::log_modes`], `modes/eigenvalues` (the twelve eigenvalues
/// of the energy Hessian of the tet given by --tet, lowest first, one series each) and
/// `world/modes/lowest` (its lowest mode but the translations, as arrows).
pub struct Recorder<'a> {
    rec: &'a RecordingStream,
    root: String,
    arrows: ArrowsMode,
    tet: usize,
    /// Each body's mesh and edges, or the one body's.
    parts: Vec<BodyPart>,
    inverted: Vec<bool>,
    colours: Vec<Rgba>,
    logged_colours: Option<Vec<Rgba>>,
    points: Vec<Vec3>,
    arrow_scratch: Vec<Arrow>,
    /// The arrows of the contacts touching, reused every frame.
    contact_scratch: Vec<Arrow>,
    modes: bool,
}

impl<'a> Recorder<'a> {
    /// Logs the static parts under `root`: coordinates, mesh topology, styles.
    pub fn new(
        rec: &'a RecordingStream,
        root: &str,
        scene: &Scene,
        simulation: &Simulation,
        arrows: ArrowsMode,
        tet: usize,
    ) -> Self {
        let log = |path: &str, what: &dyn rerun::AsComponents| {
            rec.log_static(format!("{root}{path}"), what).ok();
        };
        log("world", &rerun::ViewCoordinates::RIGHT_HAND_Y_UP());
        let size = visual::body_size(simulation.rest_positions());
        log(
            "world/particles",
            &rerun::Points3D::update_fields()
                .with_radii([rerun::Radius::new_scene_units((0.004 * size) as f32)]),
        );
        let parts = BodyPart::of(scene, simulation);
        for part in &parts {
            log(
                &format!("{}mesh", part.world),
                &rerun::Mesh3D::update_fields().with_triangle_indices(
                    part.faces.iter().map(|f| rerun::TriangleIndices::from(*f)),
                ),
            );
            log(
                &format!("{}edges", part.world),
                &rerun::LineStrips3D::update_fields()
                    .with_colors([rgba(visual::EDGE)])
                    .with_radii([rerun::Radius::new_ui_points(0.75)]),
            );
        }
        // The constraint files of the families in use, as written: what the arrows of
        // `world/gradients/<name>` are the gradient of.
        let families = simulation.families();
        for family in simulation.active().families() {
            if let Some(file) = families.file(family) {
                let text = format!(
                    "# {}\n\n{}\n\n```toml\n{}\n```",
                    families.name(family),
                    file.path.display(),
                    file.source.trim_end()
                );
                log(
                    &format!("constraints/{}", families.name(family)),
                    &rerun::TextDocument::from_markdown(text),
                );
            }
        }
        let quantities = families
            .all()
            .flat_map(|f| Quantity::of_family(families, f));
        for quantity in quantities.chain([Quantity::Correction]) {
            log(
                &arrow_path(families, quantity),
                &rerun::Arrows3D::update_fields().with_colors([rgba(quantity.colour(families))]),
            );
        }
        Recorder {
            rec,
            root: root.to_owned(),
            arrows,
            tet,
            parts,
            inverted: Vec::new(),
            colours: Vec::new(),
            logged_colours: None,
            points: Vec::new(),
            arrow_scratch: Vec::new(),
            contact_scratch: Vec::new(),
            modes: false,
        }
    }

    /// Also logs, each frame, the eigenvalues of the energy Hessian of the tet given by --tet and
    /// its lowest mode but the translations as arrows ([`tetlab_core::energy::modes::Modes`]).
    pub fn log_modes(&mut self) {
        let rec = self.rec;
        let log = |path: &str, what: &dyn rerun::AsComponents| {
            rec.log_static(format!("{}{path}", self.root), what).ok();
        };
        log(
            "modes/eigenvalues",
            &rerun::SeriesLines::new().with_names((0..12).map(|k| format!("lambda {k}"))),
        );
        log(
            "world/modes/lowest",
            &rerun::Arrows3D::update_fields().with_colors([rgba(visual::MODE)]),
        );
        self.modes = true;
    }

    /// The tet whose arrows are logged with [`ArrowsMode::Selected`].
    pub fn set_tet(&mut self, tet: usize) {
        self.tet = tet;
    }

    /// Logs the current state, whose `metrics` were measured and checked
    /// ([`Metrics::measure_sound`]), at the simulation's frame and time. Colours are logged only
    /// when they change: the viewer shows the latest value at each frame.
    pub fn log_frame(&mut self, simulation: &Simulation, metrics: &Metrics) {
        self.log_frame_at(simulation.frame(), simulation.time(), simulation, metrics);
    }

    /// Logs the current state at a given frame and time (for runs whose simulation is reset
    /// along the way, like lessons, but whose recording goes on).
    pub fn log_frame_at(
        &mut self,
        frame: u64,
        time: f64,
        simulation: &Simulation,
        metrics: &Metrics,
    ) {
        let rec = self.rec;
        rec.set_time_sequence("frame", frame as i64);
        rec.set_duration_secs("sim_time", time);
        let root = self.root.clone();
        let log = |path: &str, what: &dyn rerun::AsComponents| {
            rec.log(format!("{root}{path}"), what).ok();
        };

        self.points.clear();
        self.points
            .extend(simulation.positions().iter().map(|p| p.as_vec3()));
        visual::inverted_tets(
            simulation.positions(),
            simulation.tets(),
            &mut self.inverted,
        );
        visual::particle_colours(
            self.points.len(),
            simulation.tets(),
            &self.inverted,
            &mut self.colours,
        );
        visual::held_particle_colours(simulation, &mut self.colours);
        let colours_changed = self.logged_colours.as_ref() != Some(&self.colours);

        let particles =
            rerun::Points3D::update_fields().with_positions(self.points.iter().copied());
        if colours_changed {
            log(
                "world/particles",
                &particles.with_colors(self.colours.iter().map(|&c| rgba(c))),
            );
        } else {
            log("world/particles", &particles);
        }
        for part in &self.parts {
            let points = &self.points[part.particles.clone()];
            let mut mesh =
                rerun::Mesh3D::update_fields().with_vertex_positions(points.iter().copied());
            if colours_changed {
                let colours = &self.colours[part.particles.clone()];
                mesh = mesh.with_vertex_colors(colours.iter().map(|&c| rgba(c)));
            }
            log(&format!("{}mesh", part.world), &mesh);
            let strips = (part.strips.iter()).map(|strip| {
                strip
                    .iter()
                    .map(|&i| points[i as usize])
                    .collect::<Vec<_>>()
            });
            log(
                &format!("{}edges", part.world),
                &rerun::LineStrips3D::update_fields().with_strips(strips),
            );
        }
        if colours_changed {
            self.logged_colours = Some(self.colours.clone());
        }
        self.log_arrows(simulation);
        self.log_contacts(simulation, metrics);
        if self.modes {
            self.log_modes_now(simulation);
        }

        for (name, value) in metrics.headline() {
            log(&format!("metrics/{name}"), &rerun::Scalars::single(value));
        }
        // The energy account, one series each in one plot.
        let energy = Energy::measure(simulation);
        let parts = energy.parts(simulation.families());
        for (name, value) in parts.into_iter().chain([
            ("taken_by_ground", energy.taken.ground),
            ("taken_by_damping", energy.taken.damping),
            ("taken_by_settling", energy.taken.settling),
        ]) {
            log(&format!("energy/{name}"), &rerun::Scalars::single(value));
        }
        self.log_bodies(simulation);
    }

    /// Logs each body's headline metrics (with its contacts touching and largest penetration,
    /// where a family on contacts is active) and energy under `bodies/<name>/` (nothing for a
    /// scene of one body): [`Metrics::measure_bodies`] and [`Energy::measure_bodies`], the
    /// numbers `tetlab run --json` prints per body.
    fn log_bodies(&self, simulation: &Simulation) {
        let metrics = Metrics::measure_bodies(simulation);
        let energies = Energy::measure_bodies(simulation);
        let families = simulation.families();
        let contact =
            tetlab_core::simulation::contact::contact_families(families, simulation.active())
                .next()
                .is_some();
        let plots = self.parts.iter().filter_map(|p| p.plots.as_ref());
        for ((path, (_, metrics)), (_, energy)) in plots.zip(metrics).zip(energies) {
            let log = |name: String, value: f64| {
                (self.rec)
                    .log(
                        format!("{}{path}{name}", self.root),
                        &rerun::Scalars::single(value),
                    )
                    .ok();
            };
            for (name, value) in metrics.headline() {
                log(format!("metrics/{name}"), value);
            }
            if contact {
                log("metrics/contacts".into(), metrics.contacts as f64);
                log("metrics/max_penetration".into(), metrics.max_penetration);
            }
            for (name, value) in energy.parts(families) {
                log(format!("energy/{name}"), value);
            }
        }
    }

    /// Logs the contacts touching, where a family on contacts is active: each particle's point
    /// and its contact normal (`world/contacts`, in the contact family's colour,
    /// [`visual::contact_arrows`], as the workbench draws them), and the contacts and the
    /// largest penetration as metrics.
    fn log_contacts(&mut self, simulation: &Simulation, metrics: &Metrics) {
        let families = simulation.families();
        let Some(family) =
            tetlab_core::simulation::contact::contact_families(families, simulation.active())
                .next()
        else {
            return;
        };
        self.contact_scratch.clear();
        visual::contact_arrows(simulation, 1.0, &mut self.contact_scratch);
        let [r, g, b, a] = visual::family_colour(families, family);
        self.rec
            .log(
                format!("{}world/contacts", self.root),
                &rerun::Arrows3D::from_vectors(
                    self.contact_scratch.iter().map(|a| a.vector.as_vec3()),
                )
                .with_origins(self.contact_scratch.iter().map(|a| a.origin.as_vec3()))
                .with_colors([rerun::Color::from_unmultiplied_rgba(r, g, b, a)]),
            )
            .ok();
        for (name, value) in [
            ("contacts", metrics.contacts as f64),
            ("max_penetration", metrics.max_penetration),
        ] {
            self.rec
                .log(
                    format!("{}metrics/{name}", self.root),
                    &rerun::Scalars::single(value),
                )
                .ok();
        }
    }

    /// Logs the gradient arrows of the chosen tets, one entity per active family, and Δp of the
    /// last substep at their particles, at its true length ([`visual::selected_arrows`], as the
    /// workbench draws them).
    fn log_arrows(&mut self, simulation: &Simulation) {
        let selection = match self.arrows {
            ArrowsMode::None => return,
            ArrowsMode::Selected => visual::ArrowSelection::Tet(self.tet),
            ArrowsMode::All => visual::ArrowSelection::AllTets,
        };
        self.arrow_scratch.clear();
        visual::selected_arrows(
            simulation,
            selection,
            Some(1.0),
            Some(1.0),
            &mut self.arrow_scratch,
        );
        let active = *simulation.active();
        let families = simulation.families();
        let quantities = families
            .all()
            .filter(|&f| active.get(f))
            .flat_map(|f| Quantity::of_family(families, f))
            .chain([Quantity::Correction]);
        for quantity in quantities {
            let arrows = self.arrow_scratch.iter().filter(|a| a.quantity == quantity);
            self.rec
                .log(
                    format!("{}{}", self.root, arrow_path(families, quantity)),
                    &rerun::Arrows3D::update_fields()
                        .with_origins(arrows.clone().map(|a| a.origin.as_vec3()))
                        .with_vectors(arrows.map(|a| a.vector.as_vec3())),
                )
                .ok();
        }
    }
}

impl Recorder<'_> {
    /// The eigenvalues and lowest mode of the tet's energy Hessian now (nothing while no family
    /// is active).
    fn log_modes_now(&mut self, simulation: &Simulation) {
        let Ok(modes) = Modes::of_tet(simulation, self.tet) else {
            return;
        };
        let root = &self.root;
        self.rec
            .log(
                format!("{root}modes/eigenvalues"),
                &rerun::Scalars::new(modes.values()),
            )
            .ok();
        self.arrow_scratch.clear();
        let corners = simulation.tets()[self.tet];
        let lowest = modes.lowest_deformation();
        visual::mode_arrows(
            simulation.positions(),
            corners,
            &lowest.vector,
            1.0,
            &mut self.arrow_scratch,
        );
        let arrows = &self.arrow_scratch;
        self.rec
            .log(
                format!("{root}world/modes/lowest"),
                &rerun::Arrows3D::update_fields()
                    .with_origins(arrows.iter().map(|a| a.origin.as_vec3()))
                    .with_vectors(arrows.iter().map(|a| a.vector.as_vec3())),
            )
            .ok();
    }
}

/// Where arrows of `quantity` are logged.
fn arrow_path(families: &Families, quantity: Quantity) -> String {
    match quantity {
        Quantity::Gradient(family) => format!("world/gradients/{}", families.name(family)),
        Quantity::Disagreeing(family) => {
            let other = Quantity::disagreeing_name(families, family).to_lowercase();
            format!("world/gradients/{}-{other}", families.name(family))
        }
        Quantity::Correction => "world/corrections".to_owned(),
        Quantity::Mode => "world/modes/lowest".to_owned(),
    }
}

fn rgba(c: Rgba) -> rerun::Color {
    rerun::Color::from_unmultiplied_rgba(c[0], c[1], c[2], c[3])
}
