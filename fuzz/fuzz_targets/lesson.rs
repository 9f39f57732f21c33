//! A lesson file. Whatever the bytes, reading gives a lesson or an error naming the file and a
//! line that exists; never a panic. Scenes are built only when small (built-ins up to resolution
//! 2), so that the fuzzer's time goes to parsing; the first step's actions are applied and one
//! frame run, since a parsed lesson must run.

#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use tetlab_core::input::text_file::decode;
use tetlab_core::teaching::lesson::{Lesson, LessonRun};

#[path = "../support/small_scenes.rs"]
mod small_scenes;

use small_scenes::small;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = decode(data) else {
        return;
    };
    match Lesson::parse_with(Path::new("fuzz.toml"), text, &small) {
        Ok(lesson) => {
            assert!(!lesson.steps.is_empty());
            let mut run = LessonRun::new(&lesson);
            for &action in &lesson.steps[0].actions {
                run.apply(action);
            }
            let settings = run.simulation.settings();
            if settings.substeps * settings.iterations <= 1000 {
                run.step();
            }
        }
        Err(e) => {
            if let Some(line) = e.line {
                assert!(line >= 1 && line <= text.lines().count() + 1, "{e}");
            }
        }
    }
});
