//! Builds the lessons of `assets/lessons/*.toml` into the library, in file-name order, so that
//! adding a lesson is adding a file.

use std::fmt::Write;
use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let folder = manifest.join("../assets/lessons");
    println!("cargo:rerun-if-changed={}", folder.display());
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .expect("assets/lessons is readable")
        .map(|entry| entry.expect("assets/lessons is readable").path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    let mut code = String::from("/// The lessons in assets/lessons, in file-name order.\n");
    code += "pub const BUILTIN: &[BuiltinLesson] = &[\n";
    for path in files {
        let path = path.canonicalize().expect("a listed file exists");
        let name = path.file_name().expect("a file").to_string_lossy();
        writeln!(
            code,
            "    BuiltinLesson {{ file: {name:?}, path: {path:?}, text: include_str!({path:?}) }},",
        )
        .expect("writing to a String");
    }
    code += "];\n";
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo")).join("lessons.rs");
    std::fs::write(out, code).expect("OUT_DIR is writable");
}
