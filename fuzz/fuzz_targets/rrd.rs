//! A Rerun recording, read as `tetlab inspect` reads it (the same source file). Whatever the
//! bytes, it gives a summary or an error; never a panic, and never an allocation larger than the
//! input can justify (libFuzzer's `-malloc_limit_mb` catches one).

#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
#[path = "../../app/src/record/summary.rs"]
mod summary;

fuzz_target!(|data: &[u8]| {
    let _ = summary::Summary::decode(std::io::Cursor::new(data));
});
