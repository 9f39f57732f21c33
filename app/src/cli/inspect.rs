//! `tetlab inspect`: what a Rerun recording holds, read back with Rerun's own decoder.

use super::UsageError;
use crate::record::summary::Summary;
use std::io::Write;
use std::path::PathBuf;

/// Options of `tetlab inspect`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The recording (.rrd).
    file: PathBuf,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
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
    let w = summary
        .entities
        .keys()
        .map(|p| p.len())
        .max()
        .unwrap_or(0)
        .max(24)
        + 2;
    writeln!(
        out,
        "{:<w$}{:>7}{:>7}  components (static | per frame)",
        "entity", "static", "frames"
    )
    .map_err(io)?;
    for (path, e) in &summary.entities {
        writeln!(
            out,
            "{path:<w$}{:>7}{:>7}  {} | {}",
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
