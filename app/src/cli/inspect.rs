//! `tetlab inspect`: what a Rerun recording holds, read back with Rerun's own decoder.

use super::UsageError;
use rerun::external::re_log_encoding::Decoder;
use rerun::log::{Chunk, LogMsg};
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

/// Options of `tetlab inspect`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The recording (.rrd).
    file: PathBuf,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

/// What one entity holds.
#[derive(Debug, Default, Serialize)]
pub struct Entity {
    /// Rows logged as static (once, for all time).
    pub static_rows: usize,
    /// Components logged as static, as `Archetype:field`.
    pub static_components: Vec<String>,
    /// Rows logged on the `frame` timeline.
    pub frame_rows: usize,
    /// Components logged on the `frame` timeline.
    pub frame_components: Vec<String>,
}

/// A recording's entities, frame range, metric series and particle count.
#[derive(Debug, Default, Serialize)]
pub struct Summary {
    /// Entities by path.
    pub entities: BTreeMap<String, Entity>,
    /// The first and last value of the `frame` timeline.
    pub frames: Option<(i64, i64)>,
    /// The time series under `metrics/`: (frame, value) in frame order.
    pub metrics: BTreeMap<String, Vec<(i64, f64)>>,
    /// Particles in `world/particles` at each frame, in frame order.
    pub particles: Vec<(i64, usize)>,
}

impl Summary {
    /// Decodes the whole recording at `path`.
    pub fn read(path: &Path) -> Result<Summary, String> {
        let file = std::fs::File::open(path).map_err(|e| format!("cannot read: {e}"))?;
        let mut messages = Decoder::<LogMsg>::decode_eager(BufReader::new(file))
            .map_err(|e| format!("not a Rerun recording: {e}"))?;
        let mut summary = Summary::default();
        let mut data_messages = 0;
        for message in messages.by_ref() {
            let message = message.map_err(|e| format!("damaged recording: {e}"))?;
            if let LogMsg::ArrowMsg(store, arrow) = message {
                if store.is_blueprint() {
                    continue;
                }
                let chunk =
                    Chunk::from_arrow_msg(&arrow).map_err(|e| format!("damaged chunk: {e}"))?;
                summary.add(&chunk);
                data_messages += 1;
            }
        }
        if data_messages == 0 {
            return Err("not a Rerun recording: it holds no data".into());
        }
        // The writer ends a finished stream with a footer; a cut-off file has none.
        let footers = messages
            .rrd_manifests()
            .map_err(|e| format!("damaged footer: {e}"))?;
        if footers.is_empty() {
            return Err(
                "incomplete recording: it has no footer, so the writer did not finish".into(),
            );
        }
        for series in summary.metrics.values_mut() {
            series.sort_by_key(|(frame, _)| *frame);
        }
        summary.particles.sort_by_key(|(frame, _)| *frame);
        Ok(summary)
    }

    fn add(&mut self, chunk: &Chunk) {
        let path = chunk.entity_path().to_string();
        let path = path.trim_start_matches('/').to_owned();
        let entity = self.entities.entry(path.clone()).or_default();
        let (rows, components) = if chunk.is_static() {
            (&mut entity.static_rows, &mut entity.static_components)
        } else {
            (&mut entity.frame_rows, &mut entity.frame_components)
        };
        for descriptor in chunk.component_descriptors() {
            let name = descriptor.display_name().to_owned();
            if !components.contains(&name) {
                components.push(name);
            }
        }
        components.sort();
        if chunk.is_static() {
            *rows += chunk.num_rows();
            return;
        }
        let Some(frames) = chunk
            .timelines()
            .get(&"frame".into())
            .map(|t| t.times_raw().to_vec())
        else {
            return;
        };
        entity.frame_rows += frames.len();
        for &f in &frames {
            self.frames = Some(match self.frames {
                Some((lo, hi)) => (lo.min(f), hi.max(f)),
                None => (f, f),
            });
        }
        if path.starts_with("metrics/") {
            let values = chunk.iter_component::<rerun::components::Scalar>(
                rerun::Scalars::descriptor_scalars().component,
            );
            let series = self
                .metrics
                .entry(path.trim_start_matches("metrics/").to_owned())
                .or_default();
            for (frame, row) in frames.iter().zip(values) {
                if let Some(value) = row.first() {
                    series.push((*frame, value.0.0));
                }
            }
        } else if path == "world/particles" {
            let rows = chunk.iter_component::<rerun::components::Position3D>(
                rerun::Points3D::descriptor_positions().component,
            );
            for (frame, row) in frames.iter().zip(rows) {
                self.particles.push((*frame, row.len()));
            }
        }
    }
}

/// Prints the summary of a recording.
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let summary = Summary::read(&args.file)
        .map_err(|e| UsageError(format!("{}: {e}", args.file.display())))?;
    let io = UsageError::stdout;
    if args.json {
        serde_json::to_writer(&mut *out, &summary).map_err(|e| io(e.into()))?;
        return writeln!(out).map_err(io);
    }
    match summary.frames {
        Some((first, last)) => writeln!(out, "{}: frames {first}..={last}", args.file.display()),
        None => writeln!(out, "{}: no frames", args.file.display()),
    }
    .map_err(io)?;
    writeln!(
        out,
        "{:<26}{:>7}{:>7}  components (static | per frame)",
        "entity", "static", "frames"
    )
    .map_err(io)?;
    for (path, e) in &summary.entities {
        writeln!(
            out,
            "{path:<26}{:>7}{:>7}  {} | {}",
            e.static_rows,
            e.frame_rows,
            e.static_components.join(", "),
            e.frame_components.join(", ")
        )
        .map_err(io)?;
    }
    for (name, series) in &summary.metrics {
        if let Some((frame, value)) = series.last() {
            writeln!(out, "{name} at frame {frame}: {value}").map_err(io)?;
        }
    }
    Ok(())
}
