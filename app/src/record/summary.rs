//! A recording read back with Rerun's own decoder: its entities, frames, metric series and
//! particle counts. `tetlab inspect` prints it; `record` reads its own file with it before
//! moving the file into place.
//!
//! A recording is data from outside, so reading one is defended: no damage makes it panic, and
//! none makes it allocate more than the file holds. This file uses only Rerun's crates, serde and
//! std, so that the fuzz target of `fuzz/` compiles the very same code.

use re_chunk::Chunk;
use re_log_encoding::Decoder;
use re_log_types::LogMsg;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

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
    /// The time series under `metrics/` (named without it) and each body's under `bodies/` (named
    /// in full, `bodies/<name>/energy/total`): (frame, value) in frame order.
    pub metrics: BTreeMap<String, Vec<(i64, f64)>>,
    /// Particles in `world/particles` at each frame, in frame order.
    pub particles: Vec<(i64, usize)>,
}

impl Summary {
    /// Decodes the whole recording at `path`.
    pub fn read(path: &Path) -> Result<Summary, String> {
        let file = std::fs::File::open(path).map_err(|e| format!("cannot read: {e}"))?;
        Summary::decode(file)
    }

    /// Decodes a whole recording from `reader`. A damaged recording is an error, never a panic
    /// and never an allocation larger than the recording: its framing is checked first
    /// (`check_message_lengths`), and a panic inside Rerun's decoder (which some damaged
    /// files cause, in arrow's schema conversion) is caught and reported as damage.
    pub fn decode<R: Read + Seek>(mut reader: R) -> Result<Summary, String> {
        check_message_lengths(&mut reader)?;
        reader
            .seek(SeekFrom::Start(0))
            .map_err(|e| format!("cannot read: {e}"))?;
        untrusted(|| Summary::decode_checked(BufReader::new(reader)))
    }

    fn decode_checked(reader: impl BufRead) -> Result<Summary, String> {
        let mut messages = Decoder::<LogMsg>::decode_eager(reader)
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
        if path.starts_with("metrics/") || path.starts_with("bodies/") {
            let values = chunk.iter_component::<re_sdk_types::components::Scalar>(
                re_sdk_types::archetypes::Scalars::descriptor_scalars().component,
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
            let rows = chunk.iter_component::<re_sdk_types::components::Position3D>(
                re_sdk_types::archetypes::Points3D::descriptor_positions().component,
            );
            for (frame, row) in frames.iter().zip(rows) {
                self.particles.push((*frame, row.len()));
            }
        }
    }
}

/// Checks that nothing in an .rrd stream claims more bytes than it can hold, walking the framing
/// the way Rerun's decoder does (a stream header; messages, each a 16-byte header with its
/// length; after the end message a stream footer; then perhaps another stream), and inside each
/// message what is decoded from it ([`check_arrow_msg`], [`check_footer`]). The decoder, arrow
/// and LZ4 all allocate a buffer of the claimed length before reading, and an allocation that
/// fails aborts the process, so a damaged length would otherwise end tetlab instead of being
/// reported. Where the framing stops making sense the walk stops and leaves the verdict to the
/// decoder, which reads no further either.
fn check_message_lengths(reader: &mut (impl Read + Seek)) -> Result<(), String> {
    use re_log_encoding::{Decodable, MessageHeader, MessageKind, StreamFooter, StreamHeader};
    let io = |e: std::io::Error| format!("cannot read: {e}");
    let size = reader.seek(SeekFrom::End(0)).map_err(io)?;
    let mut at = reader.seek(SeekFrom::Start(0)).map_err(io)?;
    let mut read = |at: u64, buffer: &mut [u8]| -> Result<bool, String> {
        if at + buffer.len() as u64 > size {
            return Ok(false);
        }
        reader.seek(SeekFrom::Start(at)).map_err(io)?;
        reader.read_exact(buffer).map_err(io)?;
        Ok(true)
    };
    'streams: loop {
        let mut header = [0; StreamHeader::ENCODED_SIZE_BYTES];
        if !read(at, &mut header)?
            || StreamHeader::from_rrd_bytes(&header)
                .and_then(|h| h.to_version_and_options())
                .is_err()
        {
            return Ok(());
        }
        at += header.len() as u64;
        loop {
            let mut header = [0; MessageHeader::ENCODED_SIZE_BYTES];
            if !read(at, &mut header)? {
                return Ok(());
            }
            let Ok(message) = MessageHeader::from_rrd_bytes(&header) else {
                // Perhaps the next of several concatenated streams.
                continue 'streams;
            };
            at += header.len() as u64;
            if message.len > size - at {
                return Err(format!(
                    "incomplete recording: a message at byte {} claims {} bytes but only {} \
                     follow (the file was cut off, or the length is damaged)",
                    at - header.len() as u64,
                    message.len,
                    size - at
                ));
            }
            let damaged =
                |why: String| format!("damaged recording: the message at byte {at}: {why}");
            if matches!(message.kind, MessageKind::ArrowMsg | MessageKind::End) {
                let mut payload = vec![0; message.len as usize];
                read(at, &mut payload)?;
                match message.kind {
                    MessageKind::ArrowMsg => check_arrow_msg(&payload).map_err(damaged)?,
                    _ => check_footer(&payload).map_err(damaged)?,
                }
            }
            at += message.len;
            if message.kind == MessageKind::End {
                at += StreamFooter::ENCODED_SIZE_BYTES as u64;
                continue 'streams;
            }
        }
    }
}

/// A data message: an arrow IPC stream, maybe LZ4-compressed ([`check_ipc`]). A message that is
/// not even protobuf is left to the decoder.
fn check_arrow_msg(payload: &[u8]) -> Result<(), String> {
    use re_protos::external::prost::Message;
    let Ok(message) = re_protos::log_msg::v1alpha1::ArrowMsg::decode(payload) else {
        return Ok(());
    };
    check_ipc(
        &message.payload,
        message.compression,
        message.uncompressed_size,
    )
}

/// The footer that ends a stream: for each recording in it, an arrow IPC schema and an arrow IPC
/// table of its chunks ([`check_ipc`]).
fn check_footer(payload: &[u8]) -> Result<(), String> {
    use re_protos::external::prost::Message;
    if payload.is_empty() {
        return Ok(());
    }
    let Ok(footer) = re_protos::log_msg::v1alpha1::RrdFooter::decode(payload) else {
        return Ok(());
    };
    for manifest in &footer.manifests {
        if let Some(schema) = manifest
            .sorbet_schema
            .as_ref()
            .and_then(|s| s.arrow_schema.as_ref())
        {
            check_ipc(schema, 0, 0)?;
        }
        if let Some(part) = &manifest.data
            && let Some(payload) = &part.payload
        {
            check_ipc(payload, part.compression, part.uncompressed_size)?;
        }
    }
    Ok(())
}

/// Rerun's value for LZ4 block compression (`Compression::Lz4` of its protobuf schema).
const LZ4: i32 = 2;

/// An arrow IPC stream as Rerun stores one, LZ4-compressed when `compression` says so: the size
/// it claims uncompressed is one LZ4 can reach from these bytes (at most 255 to 1), and no IPC
/// message claims more metadata or body than follow it (arrow allocates both before reading).
/// Arrow's own buffer compression, which Rerun never writes, is refused: it too allocates what
/// it is told.
fn check_ipc(bytes: &[u8], compression: i32, uncompressed_size: u64) -> Result<(), String> {
    let decompressed;
    let bytes = if compression == LZ4 {
        let most = 255 * bytes.len() as u64 + 64;
        if uncompressed_size > most {
            return Err(format!(
                "it claims {uncompressed_size} bytes once decompressed, more than LZ4 makes of {} \
                 bytes",
                bytes.len()
            ));
        }
        decompressed = re_log_encoding::external::lz4_flex::block::decompress(
            bytes,
            uncompressed_size as usize,
        )
        .map_err(|e| format!("its LZ4 data does not decompress ({e})"))?;
        &decompressed[..]
    } else {
        bytes
    };
    let mut at = 0;
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|w| i32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    loop {
        // A message: [0xFFFFFFFF] <metadata length> <metadata> <body>; length 0 ends the stream.
        let Some(mut length) = word(at) else {
            return Ok(());
        };
        at += 4;
        if length == -1 {
            let Some(after) = word(at) else {
                return Ok(());
            };
            length = after;
            at += 4;
        }
        if length <= 0 {
            return Ok(());
        }
        let length = length as usize;
        if length > bytes.len() - at {
            return Err(format!(
                "an arrow message claims {length} bytes of metadata but only {} follow",
                bytes.len() - at
            ));
        }
        let Ok(message) = re_chunk::external::arrow::ipc::root_as_message(&bytes[at..at + length])
        else {
            return Ok(());
        };
        at += length;
        let body = message.bodyLength();
        if body < 0 || body as u64 > (bytes.len() - at) as u64 {
            return Err(format!(
                "an arrow message claims a body of {body} bytes but only {} follow",
                bytes.len() - at
            ));
        }
        let compressed = message
            .header_as_record_batch()
            .map(|batch| batch.compression().is_some())
            .or_else(|| {
                message
                    .header_as_dictionary_batch()
                    .and_then(|d| d.data())
                    .map(|batch| batch.compression().is_some())
            })
            .unwrap_or(false);
        if compressed {
            return Err(
                "an arrow message uses arrow's buffer compression, which Rerun does not \
                        write"
                    .into(),
            );
        }
        at += body as usize;
    }
}

/// Runs `decode` on data from outside, turning a panic inside it into an error (the panic's
/// message is not printed: it is reported as the file's damage instead).
fn untrusted<T>(decode: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    thread_local! {
        static QUIET: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    }
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.get() {
                previous(info);
            }
        }));
    });
    QUIET.set(true);
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode));
    QUIET.set(false);
    outcome.unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(format!(
            "damaged recording: Rerun's decoder failed on it ({what})"
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use re_chunk::external::arrow;
    use std::sync::Arc;

    /// An arrow IPC stream of one small record batch, as Rerun's messages carry.
    fn ipc_stream() -> Vec<u8> {
        let values = arrow::array::Int32Array::from(vec![1, 2, 3, 4]);
        let batch =
            arrow::array::RecordBatch::try_from_iter([("x", Arc::new(values) as _)]).unwrap();
        let mut bytes = Vec::new();
        let mut writer =
            arrow::ipc::writer::StreamWriter::try_new(&mut bytes, batch.schema_ref()).unwrap();
        writer.write(&batch).unwrap();
        writer.finish().unwrap();
        drop(writer);
        bytes
    }

    /// What the fuzzer found: arrow allocates a message's claimed body before reading it, and a
    /// failed allocation aborts the process; claimed sizes beyond the data are refused first.
    #[test]
    fn arrow_data_that_claims_more_than_it_holds_is_refused_before_it_is_decoded() {
        let stream = ipc_stream();
        assert_eq!(check_ipc(&stream, 0, 0), Ok(()));

        // The record batch's body length, patched to 2⁶² in its flatbuffer.
        let mut at = 0;
        let mut patched = stream.clone();
        loop {
            let length = i32::from_le_bytes(stream[at + 4..at + 8].try_into().unwrap()) as usize;
            let metadata = &stream[at + 8..at + 8 + length];
            let message = arrow::ipc::root_as_message(metadata).unwrap();
            if message.header_as_record_batch().is_some() {
                let body = (message.bodyLength() as u64).to_le_bytes();
                let offset = metadata
                    .windows(8)
                    .position(|w| w == body)
                    .expect("the body length is in the metadata");
                patched[at + 8 + offset..at + 16 + offset]
                    .copy_from_slice(&(1u64 << 62).to_le_bytes());
                let check = arrow::ipc::root_as_message(&patched[at + 8..at + 8 + length]);
                assert_eq!(check.unwrap().bodyLength(), 1 << 62, "patched");
                break;
            }
            at += 8 + length + message.bodyLength() as usize;
        }
        let error = check_ipc(&patched, 0, 0).unwrap_err();
        assert!(
            error.contains("claims a body of 4611686018427387904 bytes"),
            "{error}"
        );

        let mut long_metadata = stream.clone();
        long_metadata[4..8].copy_from_slice(&i32::MAX.to_le_bytes());
        let error = check_ipc(&long_metadata, 0, 0).unwrap_err();
        assert!(
            error.contains("claims 2147483647 bytes of metadata"),
            "{error}"
        );

        let compressed = re_log_encoding::external::lz4_flex::block::compress(&stream);
        assert_eq!(check_ipc(&compressed, LZ4, stream.len() as u64), Ok(()));
        let error = check_ipc(&compressed, LZ4, 1 << 40).unwrap_err();
        assert!(error.contains("more than LZ4 makes"), "{error}");
    }
}
