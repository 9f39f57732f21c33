//! `tetlab record`: the run of `tetlab run`, logged to a Rerun recording.
//!
//! `main`-style set-up lives in [`run`]; [`Recorder`] logs one simulation state per frame. The
//! file is written as `FILE.rrd.partial`, decoded in full with Rerun's own decoder to check that
//! every frame arrived, and only then renamed to `FILE.rrd`: a failed or interrupted write never
//! leaves a broken recording under the name the user asked for.

use super::UsageError;
use super::inspect::Summary;
use super::simulation_args::SimulationArgs;
use glam::Vec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rerun::RecordingStream;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use tetlab_core::constraints::Family;
use tetlab_core::metrics::Metrics;
use tetlab_core::scene::Scene;
use tetlab_core::solver::Simulation;
use tetlab_core::visual::{self, Arrow, Quantity, Rgba};

/// The viewer address `--connect` uses when given no value.
pub const DEFAULT_VIEWER: &str = "rerun+http://127.0.0.1:9876/proxy";

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

/// Options of `tetlab record`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    simulation: SimulationArgs,
    /// Write the recording to this file (.rrd).
    #[arg(
        long,
        value_name = "FILE.rrd",
        required_unless_present = "connect",
        conflicts_with = "connect"
    )]
    out: Option<PathBuf>,
    /// Stream to a running Rerun viewer instead of a file.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = DEFAULT_VIEWER)]
    connect: Option<String>,
    /// Gradient arrows to log: for the tet given by --tet (selected), every tet (all) or none.
    #[arg(long, value_enum, default_value_t = ArrowsMode::Selected)]
    arrows: ArrowsMode,
    /// The tet whose gradient arrows are logged with --arrows selected.
    #[arg(
        long,
        default_value_t = 0,
        value_name = "K",
        allow_hyphen_values = true
    )]
    tet: i64,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Exit status of a run stopped by Ctrl-C (128 + SIGINT).
pub const INTERRUPTED: u8 = 130;

/// How a recording ended.
pub enum Ending {
    /// Every frame was recorded.
    Complete,
    /// Stopped by a signal; the file holds every frame up to then.
    Interrupted,
}

/// Records the run and writes or streams it. Returns how it ended.
pub fn run(args: &Args, out: &mut impl Write) -> Result<Ending, UsageError> {
    let (scene, mut simulation) = args.simulation.build()?;
    let tets = simulation.tets().len() as i64;
    if !(0..tets).contains(&args.tet) {
        return Err(UsageError(format!(
            "--tet: {} is out of range: the scene has tets 0..={}",
            args.tet,
            tets - 1
        )));
    }
    let destination = match (&args.out, &args.connect) {
        (_, Some(address)) => Destination::Viewer(address.clone()),
        (Some(path), None) => Destination::File {
            path: path.clone(),
            flag: "--out",
        },
        (None, None) => unreachable!("clap requires --out or --connect"),
    };
    let session = Session::open(destination, args.simulation.frames, args.quiet)?;
    let rec = session.rec();
    send_layout(rec, &[""]);
    describe(rec, &scene, &simulation, args);
    let mut recorder = Recorder::new(rec, "", &scene, &simulation, args.arrows, args.tet as usize);
    recorder.log_frame(&simulation);
    for _ in 0..args.simulation.frames {
        if session.interrupted() {
            break;
        }
        if let Err(diverged) = SimulationArgs::step(&mut simulation) {
            session.close(simulation.frame() - 1, out)?;
            return Err(diverged);
        }
        recorder.log_frame(&simulation);
        session.advance();
    }
    session.close(simulation.frame(), out)
}

/// The static description of a run: scene, sizes, perturbation, settings, arrows.
fn describe(rec: &RecordingStream, scene: &Scene, simulation: &Simulation, args: &Args) {
    let perturbation = args
        .simulation
        .perturb
        .map(|p| p.to_string())
        .unwrap_or_else(|| "none".into());
    let notes: String = scene.notes.iter().map(|n| format!("\n- {n}")).collect();
    let text = format!(
        "# tetlab run\n\nscene **{}**: {} particles, {} tets, {} edges{notes}\n\nperturbation: {perturbation}\n\n{}\n\ngradient arrows: {:?}, tet {}",
        scene.name,
        simulation.positions().len(),
        simulation.tets().len(),
        simulation.edges.len(),
        args.simulation.describe(),
        args.arrows,
        args.tet
    );
    rec.log_static("run", &rerun::TextDocument::from_markdown(text))
        .ok();
}

/// Where a recording goes.
pub enum Destination {
    /// A .rrd file, named by the option `flag` in messages.
    File {
        /// The file.
        path: PathBuf,
        /// The option that named it (`--out`, `--record`).
        flag: &'static str,
    },
    /// A running viewer at this address.
    Viewer(String),
}

/// A recording in progress: the stream, what watches it (write errors, Ctrl-C), a progress bar.
/// A file is written as `FILE.partial` and moved into place by [`Session::close`] only once Rerun's
/// decoder has read every frame back.
pub struct Session {
    target: Target,
    rec: RecordingStream,
    writer_errors: WriterErrors,
    interrupted: Arc<AtomicBool>,
    progress: Progress,
}

impl Session {
    /// Opens the destination for a recording of about `frames` frames.
    pub fn open(destination: Destination, frames: u64, quiet: bool) -> Result<Session, UsageError> {
        let interrupted = interrupt_flag()?;
        let writer_errors = WriterErrors::install();
        let target = Target::new(destination)?;
        let rec = target.open()?;
        Ok(Session {
            target,
            rec,
            writer_errors,
            interrupted,
            progress: Progress::new(frames, quiet),
        })
    }

    /// The stream to log to.
    pub fn rec(&self) -> &RecordingStream {
        &self.rec
    }

    /// Whether Ctrl-C (or SIGTERM) asked to stop.
    pub fn interrupted(&self) -> bool {
        self.interrupted.load(Ordering::SeqCst)
    }

    /// One more frame recorded.
    pub fn advance(&self) {
        self.progress.advance();
    }

    /// Flushes, checks and closes the recording, whose last frame is `last_frame`; says so on
    /// `out`, and on stderr when it was interrupted.
    pub fn close(self, last_frame: u64, out: &mut impl Write) -> Result<Ending, UsageError> {
        self.progress.finish();
        let interrupted = self.interrupted();
        self.target
            .close(self.rec, last_frame, &self.writer_errors, out)?;
        if interrupted {
            eprintln!("interrupted: the recording holds frames 0..={last_frame}");
            Ok(Ending::Interrupted)
        } else {
            Ok(Ending::Complete)
        }
    }
}

/// Where the recording goes.
enum Target {
    File {
        path: PathBuf,
        partial: PathBuf,
        flag: &'static str,
    },
    Viewer {
        url: String,
    },
}

impl Target {
    fn new(destination: Destination) -> Result<Target, UsageError> {
        let (path, flag) = match destination {
            Destination::Viewer(address) => {
                let url = if address.contains("://") {
                    address
                } else {
                    format!("rerun+http://{address}/proxy")
                };
                return Ok(Target::Viewer { url });
            }
            Destination::File { path, flag } => (path, flag),
        };
        if path.is_dir() {
            return Err(UsageError(format!(
                "{flag} {}: is a directory",
                path.display()
            )));
        }
        let mut partial = path.clone().into_os_string();
        partial.push(".partial");
        Ok(Target::File {
            path,
            partial: partial.into(),
            flag,
        })
    }

    fn open(&self) -> Result<RecordingStream, UsageError> {
        let builder = rerun::RecordingStreamBuilder::new("tetlab");
        match self {
            Target::File {
                path,
                partial,
                flag,
            } => builder.save(partial).map_err(|e| {
                UsageError(format!(
                    "{flag} {}: cannot create the file: {}",
                    path.display(),
                    io_cause(&e)
                ))
            }),
            Target::Viewer { url } => builder
                .connect_grpc_opts(url.clone())
                .map_err(|e| UsageError(format!("--connect {url}: {e}"))),
        }
    }

    /// Flushes and closes the stream; for a file, verifies it and moves it into place.
    fn close(
        self,
        rec: RecordingStream,
        last_frame: u64,
        writer_errors: &WriterErrors,
        out: &mut impl Write,
    ) -> Result<(), UsageError> {
        let flushed = rec.flush_blocking();
        drop(rec);
        let flushed = flushed.map_err(|e| writer_errors.first().unwrap_or_else(|| e.to_string()));
        match self {
            Target::Viewer { url } => flushed.map_err(|e| {
                UsageError(format!(
                    "--connect {url}: the viewer did not receive the recording: {e}"
                ))
            }),
            Target::File {
                path,
                partial,
                flag,
            } => {
                let verified = flushed
                    .and_then(|()| Summary::read(&partial).map_err(|e| e.to_string()))
                    .and_then(|summary| match summary.frames {
                        Some((_, last)) if last == last_frame as i64 => Ok(summary),
                        other => Err(format!(
                            "expected frames up to {last_frame}, found {other:?}"
                        )),
                    });
                let summary = match verified {
                    Ok(summary) => summary,
                    Err(cause) => {
                        let _ = std::fs::remove_file(&partial);
                        return Err(UsageError(format!(
                            "{flag} {}: the recording could not be written completely ({cause}); nothing was kept",
                            path.display()
                        )));
                    }
                };
                std::fs::rename(&partial, &path).map_err(|e| {
                    UsageError(format!(
                        "{flag} {}: cannot move the finished recording into place: {e}",
                        path.display()
                    ))
                })?;
                let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
                writeln!(
                    out,
                    "wrote {}: frames 0..={last_frame}, {} entities, {bytes} bytes; open it with: rerun {}",
                    path.display(),
                    summary.entities.len(),
                    path.display()
                )
                .map_err(UsageError::stdout)
            }
        }
    }
}

/// The innermost cause of a rerun error, for a one-line message.
fn io_cause(error: &dyn std::error::Error) -> String {
    let mut cause = error;
    while let Some(source) = cause.source() {
        cause = source;
    }
    cause.to_string()
}

/// Errors that rerun's writer thread reports as tracing events (it has no other way to say that a
/// write failed, e.g. on a full disk), kept so the one-line error can name the cause.
#[derive(Clone, Default)]
struct WriterErrors(Arc<std::sync::Mutex<Vec<String>>>);

impl WriterErrors {
    /// Installs a subscriber that keeps ERROR events and prints nothing.
    fn install() -> WriterErrors {
        use tracing_subscriber::layer::SubscriberExt;
        let errors = WriterErrors::default();
        let subscriber = tracing_subscriber::registry().with(errors.clone());
        // Only fails if a subscriber is already set; then causes are simply not captured.
        let _ = tracing::subscriber::set_global_default(subscriber);
        errors
    }

    fn first(&self) -> Option<String> {
        self.0.lock().ok()?.first().cloned()
    }
}

impl<S: tracing::Subscriber> tracing_subscriber::Layer<S> for WriterErrors {
    fn on_event(&self, event: &tracing::Event<'_>, _: tracing_subscriber::layer::Context<'_, S>) {
        if *event.metadata().level() != tracing::Level::ERROR {
            return;
        }
        struct Message(String);
        impl tracing::field::Visit for Message {
            fn record_debug(&mut self, field: &tracing::field::Field, value: &dyn std::fmt::Debug) {
                if field.name() == "message" {
                    self.0 = format!("{value:?}");
                }
            }
        }
        let mut message = Message(String::new());
        event.record(&mut message);
        if let Ok(mut errors) = self.0.lock() {
            errors.push(message.0);
        }
    }
}

/// Set by Ctrl-C (SIGINT) or SIGTERM; checked between frames.
fn interrupt_flag() -> Result<Arc<AtomicBool>, UsageError> {
    let flag = Arc::new(AtomicBool::new(false));
    let handler_flag = flag.clone();
    ctrlc::set_handler(move || handler_flag.store(true, Ordering::SeqCst))
        .map_err(|e| UsageError(format!("cannot watch for Ctrl-C: {e}")))?;
    Ok(flag)
}

/// A progress bar on stderr, shown only on a terminal, without --quiet, and once a run has taken
/// more than half a second.
struct Progress {
    bar: ProgressBar,
    started: Instant,
    shown: bool,
    wanted: bool,
}

impl Progress {
    fn new(frames: u64, quiet: bool) -> Self {
        let bar = ProgressBar::with_draw_target(Some(frames), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template(
                "recording {bar:40} {pos}/{len} frames, {per_sec}, {eta} left",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        Progress {
            bar,
            started: Instant::now(),
            shown: false,
            wanted: !quiet && std::io::stderr().is_terminal(),
        }
    }

    fn advance(&self) {
        self.bar.inc(1);
        if self.wanted && !self.shown && self.started.elapsed() > Duration::from_millis(500) {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// Logs a simulation to a recording: static data once, what changes every frame.
///
/// Entities, under a root (empty, or e.g. `compare/` for a second simulation): `world` (view
/// coordinates, y up; the viewer draws its grid on y = 0, the ground), `world/particles`,
/// `world/mesh` and `world/edges` (all faces and edges of a small mesh, the surface of a large
/// one, as [`visual::display_faces`] and [`visual::display_edges`] choose),
/// `world/gradients/<family>`, `world/corrections` (Δp of the last substep, at its true length),
/// `metrics/<name>`.
pub struct Recorder<'a> {
    rec: &'a RecordingStream,
    root: String,
    arrows: ArrowsMode,
    tet: usize,
    edge_strips: Vec<Vec<u32>>,
    inverted: Vec<bool>,
    colours: Vec<Rgba>,
    logged_colours: Option<Vec<Rgba>>,
    points: Vec<Vec3>,
    arrow_scratch: Vec<Arrow>,
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
        let faces = visual::display_faces(&scene.mesh);
        log(
            "world/mesh",
            &rerun::Mesh3D::update_fields()
                .with_triangle_indices(faces.iter().map(|f| rerun::TriangleIndices::from(*f))),
        );
        log(
            "world/edges",
            &rerun::LineStrips3D::update_fields()
                .with_colors([rgba(visual::EDGE)])
                .with_radii([rerun::Radius::new_ui_points(0.75)]),
        );
        let quantities = Family::ALL.map(Quantity::Gradient);
        for quantity in quantities.into_iter().chain([Quantity::Correction]) {
            log(
                &arrow_path(quantity),
                &rerun::Arrows3D::update_fields().with_colors([rgba(quantity.colour())]),
            );
        }
        Recorder {
            rec,
            root: root.to_owned(),
            arrows,
            tet,
            edge_strips: visual::edge_strips(&visual::display_edges(&scene.mesh)),
            inverted: Vec::new(),
            colours: Vec::new(),
            logged_colours: None,
            points: Vec::new(),
            arrow_scratch: Vec::new(),
        }
    }

    /// The tet whose arrows are logged with [`ArrowsMode::Selected`].
    pub fn set_tet(&mut self, tet: usize) {
        self.tet = tet;
    }

    /// Logs the current state at the simulation's frame and time. Colours are logged only when
    /// they change: the viewer shows the latest value at each frame.
    pub fn log_frame(&mut self, simulation: &Simulation) {
        self.log_frame_at(simulation.frame(), simulation.time(), simulation);
    }

    /// Logs the current state at a given frame and time (for runs whose simulation is reset
    /// along the way, like lessons, but whose recording goes on).
    pub fn log_frame_at(&mut self, frame: u64, time: f64, simulation: &Simulation) {
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
        let colours_changed = self.logged_colours.as_ref() != Some(&self.colours);

        let mut particles =
            rerun::Points3D::update_fields().with_positions(self.points.iter().copied());
        let mut mesh =
            rerun::Mesh3D::update_fields().with_vertex_positions(self.points.iter().copied());
        if colours_changed {
            particles = particles.with_colors(self.colours.iter().map(|&c| rgba(c)));
            mesh = mesh.with_vertex_colors(self.colours.iter().map(|&c| rgba(c)));
            self.logged_colours = Some(self.colours.clone());
        }
        log("world/particles", &particles);
        log("world/mesh", &mesh);
        log(
            "world/edges",
            &rerun::LineStrips3D::update_fields().with_strips(self.edge_strips.iter().map(
                |strip| {
                    strip
                        .iter()
                        .map(|&i| self.points[i as usize])
                        .collect::<Vec<_>>()
                },
            )),
        );
        self.log_arrows(simulation);

        for (name, value) in Metrics::measure(simulation).headline() {
            log(&format!("metrics/{name}"), &rerun::Scalars::single(value));
        }
    }

    /// Logs the gradient arrows of the chosen tets, one entity per active family, and Δp of the
    /// last substep at their particles, at its true length.
    fn log_arrows(&mut self, simulation: &Simulation) {
        let tets = match self.arrows {
            ArrowsMode::None => return,
            ArrowsMode::Selected => self.tet..self.tet + 1,
            ArrowsMode::All => 0..simulation.tets().len(),
        };
        let active = simulation.settings().active;
        self.arrow_scratch.clear();
        for family in Family::ALL.into_iter().filter(|&f| active.get(f)) {
            for tet in tets.clone() {
                visual::tet_gradient_arrows(simulation, tet, family, 1.0, &mut self.arrow_scratch);
            }
        }
        match self.arrows {
            ArrowsMode::All => {
                let particles = 0..simulation.positions().len() as u32;
                visual::correction_arrows(simulation, particles, 1.0, &mut self.arrow_scratch);
            }
            _ => {
                let corners = simulation.tets()[self.tet];
                visual::correction_arrows(simulation, corners, 1.0, &mut self.arrow_scratch);
            }
        }
        let quantities = Family::ALL
            .into_iter()
            .filter(|&f| active.get(f))
            .map(Quantity::Gradient)
            .chain([Quantity::Correction]);
        for quantity in quantities {
            let arrows = self.arrow_scratch.iter().filter(|a| a.quantity == quantity);
            self.rec
                .log(
                    format!("{}{}", self.root, arrow_path(quantity)),
                    &rerun::Arrows3D::update_fields()
                        .with_origins(arrows.clone().map(|a| a.origin.as_vec3()))
                        .with_vectors(arrows.map(|a| a.vector.as_vec3())),
                )
                .ok();
        }
    }
}

/// Where arrows of `quantity` are logged.
fn arrow_path(quantity: Quantity) -> String {
    match quantity {
        Quantity::Gradient(family) => format!("world/gradients/{}", family.short_name()),
        Quantity::Correction => "world/corrections".to_owned(),
    }
}

fn rgba(c: Rgba) -> rerun::Color {
    rerun::Color::from_unmultiplied_rgba(c[0], c[1], c[2], c[3])
}

/// The default layout: a 3D view per root (side by side) on the left, the four metrics stacked on
/// the right (each plot shows the metric of every root).
pub fn send_layout(rec: &RecordingStream, roots: &[&str]) {
    use rerun::blueprint::{
        Blueprint, BlueprintActivation, Horizontal, Spatial3DView, TimeSeriesView, Vertical,
    };
    let plots = Metrics::default().headline().map(|(name, _)| {
        let contents: Vec<String> = roots
            .iter()
            .map(|root| format!("+ {root}metrics/{name}"))
            .collect();
        TimeSeriesView::new(name.replace('_', " "))
            .with_contents(contents)
            .into()
    });
    let views = roots.iter().map(|root| {
        let title = if root.is_empty() {
            "soft body"
        } else {
            root.trim_end_matches('/')
        };
        Spatial3DView::new(title)
            .with_origin(format!("{root}world"))
            .into()
    });
    let layout = Horizontal::new([Horizontal::new(views).into(), Vertical::new(plots).into()])
        .with_column_shares([3.0, 2.0]);
    Blueprint::new(layout)
        .send(rec, BlueprintActivation::default())
        .ok();
}
