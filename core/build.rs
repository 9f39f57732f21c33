//! Builds the lessons of `assets/lessons/*.toml`, the example constraint files of
//! `assets/constraints/*.toml` and the scene files of `assets/scenes/*.toml` into the library, in file-name order, so that adding a lesson or
//! an example is adding a file (and so that the lessons that name an example find it where there
//! is no file system, in the browser).

use std::fmt::Write;
use std::path::{Path, PathBuf};

/// The `.toml` files of `folder`, in file-name order, as absolute paths.
fn toml_files(folder: &Path) -> Vec<PathBuf> {
    println!("cargo:rerun-if-changed={}", folder.display());
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .unwrap_or_else(|e| panic!("{} is readable: {e}", folder.display()))
        .map(|entry| entry.expect("the folder is readable").path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .map(|path| path.canonicalize().expect("a listed file exists"))
        .collect();
    files.sort();
    files
}

/// `const NAME: &[TYPE] = &[TYPE { file, path, text }, …];` for the files of `folder`.
fn table(name: &str, kind: &str, doc: &str, folder: &Path) -> String {
    let mut code = format!("/// {doc}\npub const {name}: &[{kind}] = &[\n");
    for path in toml_files(folder) {
        let file = path.file_name().expect("a file").to_string_lossy();
        writeln!(
            code,
            "    {kind} {{ file: {file:?}, path: {path:?}, text: include_str!({path:?}) }},",
        )
        .expect("writing to a String");
    }
    code += "];\n";
    code
}

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("set by cargo"));
    // (the constant, its type, what it holds, the folder, the file it is written to)
    let tables = [
        (
            "BUILTIN",
            "BuiltinLesson",
            "The lessons in assets/lessons",
            "lessons",
            "lessons.rs",
        ),
        (
            "EXAMPLES",
            "Example",
            "The example constraint files in assets/constraints",
            "constraints",
            "constraint_examples.rs",
        ),
        (
            "SHIPPED",
            "ShippedScene",
            "The scene files in assets/scenes",
            "scenes",
            "shipped_scenes.rs",
        ),
    ];
    for (name, kind, what, folder, file) in tables {
        let doc = format!("{what}, in file-name order.");
        let code = table(name, kind, &doc, &manifest.join("../assets").join(folder));
        std::fs::write(out.join(file), code).expect("OUT_DIR is writable");
    }
}
