//! A recording in progress, written to a file or streamed to a viewer. A file is written as
//! `FILE.partial`, decoded in full with Rerun's own decoder to check that every frame arrived
//! ([`super::summary`]), and only then renamed to `FILE`: a failed or interrupted write never
//! leaves a broken recording under the name the user asked for, and never replaces what is not
//! a regular file. Ctrl-C (and SIGTERM) stop after the current frame; a write past the file-size
//! limit fails rather than killing tetlab, and the file is written by [`super::file_writer`],
//! which reports a failed write at once instead of hanging.

use super::file_writer::{FileWriter, WriteFailure};
use super::summary::Summary;
use crate::cli::UsageError;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rerun::RecordingStream;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Exit status of a run stopped by Ctrl-C (128 + SIGINT).
pub const INTERRUPTED: u8 = 130;

/// How a recording ended.
pub enum Ending {
    /// Every frame was recorded.
    Complete,
    /// Stopped by a signal; the file holds every frame up to then.
    Interrupted,
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
    failure: WriteFailure,
    interrupted: Arc<AtomicBool>,
    progress: Progress,
}

impl Session {
    /// Opens the destination for a recording of about `frames` frames.
    pub fn open(destination: Destination, frames: u64, quiet: bool) -> Result<Session, UsageError> {
        let interrupted = interrupt_flag()?;
        survive_file_size_limit()?;
        let target = Target::new(destination)?;
        let (rec, failure) = target.open()?;
        Ok(Session {
            target,
            rec,
            failure,
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

    /// Whether to stop recording: Ctrl-C or SIGTERM asked to, or a write of the file failed
    /// (a full disk), after which nothing more can be kept and [`Session::close`] says why.
    pub fn should_stop(&self) -> bool {
        self.interrupted() || self.failure.get().is_some()
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
        let kept = self.target.close(self.rec, last_frame, &self.failure)?;
        if let Some(kept) = kept {
            writeln!(out, "wrote {kept}").map_err(UsageError::stdout)?;
        }
        if interrupted {
            eprintln!("interrupted: the recording holds frames 0..={last_frame}");
            Ok(Ending::Interrupted)
        } else {
            Ok(Ending::Complete)
        }
    }

    /// Closes the recording of a run that failed after frame `last_frame` (it diverged): what was
    /// recorded up to then is checked and kept, and the error says so. Nothing goes to stdout,
    /// since the run did not succeed.
    pub fn close_after(self, last_frame: u64, failure: UsageError) -> UsageError {
        self.progress.finish();
        match self.target.close(self.rec, last_frame, &self.failure) {
            Ok(Some(kept)) => UsageError(format!(
                "{}; kept the recording up to it: {kept}",
                failure.0
            )),
            Ok(None) => failure,
            Err(UsageError(also)) => UsageError(format!("{}; and {also}", failure.0)),
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
        let path = writable_target(path, flag)?;
        let mut partial = path.clone().into_os_string();
        partial.push(".partial");
        let partial = writable_target(partial.into(), flag)?;
        Ok(Target::File {
            path,
            partial,
            flag,
        })
    }

    /// The stream, and where a failed write of its file is kept (never set for a viewer).
    fn open(&self) -> Result<(RecordingStream, WriteFailure), UsageError> {
        let builder = rerun::RecordingStreamBuilder::new("tetlab");
        match self {
            Target::File {
                path,
                partial,
                flag,
            } => {
                let cannot = |cause: String| {
                    // It may have been created before the first write failed (a file-size limit).
                    let _ = std::fs::remove_file(partial);
                    UsageError(format!(
                        "{flag} {}: cannot create the file: {cause}",
                        path.display()
                    ))
                };
                let (writer, failure) =
                    FileWriter::create(partial).map_err(|e| cannot(e.to_string()))?;
                let sinks: Vec<Box<dyn rerun::sink::LogSink>> = vec![Box::new(writer)];
                let rec = builder.set_sinks(sinks).map_err(|e| cannot(io_cause(&e)))?;
                Ok((rec, failure))
            }
            Target::Viewer { url } => builder
                .connect_grpc_opts(url.clone())
                .map(|rec| (rec, WriteFailure::default()))
                .map_err(|e| UsageError(format!("--connect {url}: {e}"))),
        }
    }

    /// Flushes and closes the stream; for a file, verifies it, moves it into place and returns
    /// what was written (`FILE: frames 0..=N, …`).
    fn close(
        self,
        rec: RecordingStream,
        last_frame: u64,
        failure: &WriteFailure,
    ) -> Result<Option<String>, UsageError> {
        let flushed = rec.flush_blocking();
        // Dropping the last handle of the stream drops its sink, which writes the file's footer.
        drop(rec);
        let flushed = flushed
            .map_err(|e| failure.get().unwrap_or_else(|| e.to_string()))
            .and_then(|()| failure.get().map_or(Ok(()), Err));
        match self {
            Target::Viewer { url } => flushed.map(|()| None).map_err(|e| {
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
                Ok(Some(format!(
                    "{}: frames 0..={last_frame}, {} entities, {bytes} bytes; open it with: rerun {}",
                    path.display(),
                    summary.entities.len(),
                    path.display()
                )))
            }
        }
    }
}

/// `path` if a recording may be written there: nothing there yet, or a regular file (replaced).
/// A symbolic link to a regular file stands for that file (so the link keeps pointing at the new
/// recording). Anything else (a directory, a device such as /dev/null, a named pipe, a socket)
/// is refused: renaming the finished recording over it would replace it.
fn writable_target(path: PathBuf, flag: &str) -> Result<PathBuf, UsageError> {
    let refuse = |what: &str| {
        Err(UsageError(format!(
            "{flag} {}: is {what}; a recording is written only to a new or a regular file",
            path.display()
        )))
    };
    let Ok(entry) = std::fs::symlink_metadata(&path) else {
        return Ok(path);
    };
    if entry.file_type().is_symlink() {
        return match std::fs::metadata(&path) {
            Ok(target) if target.is_file() => std::fs::canonicalize(&path)
                .map_err(|e| UsageError(format!("{flag} {}: {e}", path.display()))),
            Ok(target) => refuse(&format!(
                "a symbolic link to {}",
                kind_of_file(target.file_type())
            )),
            Err(_) => refuse("a symbolic link to nothing"),
        };
    }
    if entry.is_file() {
        Ok(path)
    } else {
        refuse(kind_of_file(entry.file_type()))
    }
}

/// What a file that is not a regular file is, for a message.
fn kind_of_file(file_type: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a named pipe (FIFO)";
        }
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    if file_type.is_dir() {
        "a directory"
    } else {
        "not a regular file"
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

/// Set by Ctrl-C (SIGINT) or SIGTERM; checked between frames.
fn interrupt_flag() -> Result<Arc<AtomicBool>, UsageError> {
    let flag = Arc::new(AtomicBool::new(false));
    let handler_flag = flag.clone();
    ctrlc::set_handler(move || handler_flag.store(true, Ordering::SeqCst))
        .map_err(|e| UsageError(format!("cannot watch for Ctrl-C: {e}")))?;
    Ok(flag)
}

/// A write past the file-size limit (`ulimit -f`) raises SIGXFSZ, which by default kills the
/// process before it can remove its `.partial` file. With a handler installed the write fails
/// instead (EFBIG), and the recording ends like any other failed write: an error, nothing kept.
fn survive_file_size_limit() -> Result<(), UsageError> {
    #[cfg(unix)]
    signal_hook::flag::register(
        signal_hook::consts::SIGXFSZ,
        Arc::new(AtomicBool::new(false)),
    )
    .map_err(|e| UsageError(format!("cannot watch for the file-size limit: {e}")))?;
    Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::{ArrowsMode, Recorder};
    use tetlab_core::measures::metrics::Metrics;
    use tetlab_core::scene::{Builtin, Scene};
    use tetlab_core::simulation::{Settings, Simulation};

    /// A run that fails part way (it diverged) keeps the frames recorded before, checked, and
    /// says so in its one-line error; nothing goes to stdout (it used to print "wrote …" first).
    #[test]
    fn a_failed_run_keeps_what_it_recorded_and_says_so_in_the_error() {
        let dir = std::env::temp_dir().join(format!("tetlab-session-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("failed.rrd");
        let destination = Destination::File {
            path: path.clone(),
            flag: "--out",
        };
        let session = Session::open(destination, 2, true).unwrap();
        let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
        let mut simulation = Simulation::new(&scene, Settings::default());
        {
            let mut recorder =
                Recorder::new(session.rec(), "", &scene, &simulation, ArrowsMode::None, 0);
            for _ in 0..2 {
                recorder.log_frame(&simulation, &Metrics::measure(&simulation));
                simulation.step();
            }
        }
        let failure = UsageError("the simulation diverged at frame 2: …".into());
        let error = session.close_after(1, failure);
        assert!(
            error.0.starts_with(
                "the simulation diverged at frame 2: …; kept the recording up to it: "
            ),
            "{}",
            error.0
        );
        assert!(error.0.contains("frames 0..=1"), "{}", error.0);
        let summary = Summary::read(&path).unwrap();
        assert_eq!(summary.frames, Some((0, 1)));
    }
}
