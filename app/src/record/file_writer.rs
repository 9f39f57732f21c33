//! The sink that writes a recording to its file: Rerun's own encoder, called on the recording
//! stream's forwarding thread, with the first write error kept for the message.
//!
//! Why not Rerun's `FileSink` (0.36.3): its writer thread returns at the first failed write (a
//! full disk, `ulimit -f`), dropping its receiver while a flush request may already wait in the
//! channel. A message left in a crossbeam channel whose receiver is gone is not dropped while a
//! sender lives, so the flush's reply channel never disconnects, and the stream's forwarding
//! thread, which waits for that reply with no timeout, blocks forever; dropping the stream then
//! joins that thread, and `tetlab record` hung (seen in 27 of 30 runs under `ulimit -f 64`).
//! Writing on the forwarding thread itself leaves no second thread to wait for: a failed write
//! is remembered, later messages are dropped, and the flush reports the failure at once.

use re_log_encoding::{Encoder, EncodingOptions};
use re_log_types::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// What went wrong with a recording's file, shared with whoever closes the recording: the first
/// failure of a write, a flush or the footer written when the sink is dropped.
#[derive(Clone, Debug, Default)]
pub struct WriteFailure(Arc<Mutex<Option<String>>>);

impl WriteFailure {
    /// The first failure, if any.
    pub fn get(&self) -> Option<String> {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    fn set(&self, failure: String) {
        let mut first = self.0.lock().unwrap_or_else(|e| e.into_inner());
        first.get_or_insert(failure);
    }
}

/// A [`LogSink`] that encodes every message into one `.rrd` file as it arrives.
pub struct FileWriter {
    encoder: Mutex<Option<Encoder<BufWriter<File>>>>,
    failure: WriteFailure,
}

impl FileWriter {
    /// Creates the file at `path` (replacing one that is there) and writes the stream header;
    /// failures after this are kept in the returned [`WriteFailure`].
    ///
    /// # Errors
    /// When the file cannot be created or cannot take the header.
    pub fn create(path: &Path) -> std::io::Result<(FileWriter, WriteFailure)> {
        let file = BufWriter::new(File::create(path)?);
        let mut encoder = Encoder::new_eager(
            rerun::build_info().version,
            EncodingOptions::PROTOBUF_COMPRESSED,
            file,
        )
        .map_err(std::io::Error::other)?;
        // The header out of the buffer now, so that a file that cannot take even that (no room
        // at all) is refused here, before the run.
        encoder.flush_blocking().map_err(|e| match e {
            re_log_encoding::EncodeError::Write(e) => e,
            other => std::io::Error::other(other),
        })?;
        let failure = WriteFailure::default();
        let writer = FileWriter {
            encoder: Mutex::new(Some(encoder)),
            failure: failure.clone(),
        };
        Ok((writer, failure))
    }

    /// Runs `write` on the encoder while it is sound; on its first error the encoder is dropped
    /// (nothing more is written) and the error kept.
    fn with_encoder(
        &self,
        what: &str,
        write: impl FnOnce(&mut Encoder<BufWriter<File>>) -> Result<(), String>,
    ) {
        let mut slot = self.encoder.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(encoder) = slot.as_mut()
            && let Err(error) = write(encoder)
        {
            self.failure.set(format!("{what}: {error}"));
            // Dropping it tries to write the footer once more, which fails the same way.
            *slot = None;
        }
    }
}

impl LogSink for FileWriter {
    fn send(&self, msg: LogMsg) {
        self.with_encoder("a write failed", |encoder| {
            encoder.append(&msg).map(|_| ()).map_err(|e| e.to_string())
        });
    }

    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        self.with_encoder("a flush failed", |encoder| {
            encoder.flush_blocking().map_err(|e| e.to_string())
        });
        match self.failure.get() {
            Some(message) => Err(SinkFlushError::Failed { message }),
            None => Ok(()),
        }
    }
}

impl Drop for FileWriter {
    /// Writes the footer and flushes, once the stream is done with the sink.
    fn drop(&mut self) {
        self.with_encoder("the end of the file could not be written", |encoder| {
            encoder.finish().map_err(|e| e.to_string())?;
            encoder.flush_blocking().map_err(|e| e.to_string())
        });
    }
}

impl std::fmt::Debug for FileWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FileWriter")
            .field("failure", &self.failure.get())
            .finish()
    }
}
