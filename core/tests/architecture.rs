//! The maps stay true: every file that `docs/architecture.md`'s reading map names exists and
//! defines the names that follow it, every folder of its layers exists, and the README's layout
//! table has a line for every folder of `core/src/` and names only paths that exist.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The `code` spans of a line of Markdown.
fn code_spans(line: &str) -> Vec<&str> {
    line.split('`').skip(1).step_by(2).collect()
}

/// Whether `source` defines `name`: a function, type, trait, constant or static of that name.
fn defines(source: &str, name: &str) -> bool {
    ["fn", "struct", "enum", "trait", "const", "static", "type"]
        .iter()
        .any(|keyword| {
            source
                .match_indices(&format!("{keyword} {name}"))
                .any(|(at, found)| {
                    let after = source[at + found.len()..].chars().next();
                    let before = source[..at].chars().next_back();
                    after.is_none_or(|c| !c.is_alphanumeric() && c != '_')
                        && before.is_none_or(|c| !c.is_alphanumeric() && c != '_')
                })
        })
}

#[test]
fn the_reading_map_names_files_and_names_that_exist() {
    let map = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let mut checked = 0;
    for line in map.lines().filter(|l| l.starts_with("- **")) {
        let mut file: Option<(String, String)> = None;
        for span in code_spans(line) {
            if span.ends_with(".rs") {
                let path = root().join(span);
                let source = std::fs::read_to_string(&path)
                    .unwrap_or_else(|e| panic!("{span} (in the map: {line}): {e}"));
                file = Some((span.to_owned(), source));
            } else {
                let (path, source) = file
                    .as_ref()
                    .unwrap_or_else(|| panic!("`{span}` follows no file in: {line}"));
                assert!(defines(source, span), "{path} does not define `{span}`");
                checked += 1;
            }
        }
    }
    assert!(
        checked >= 40,
        "the map names {checked} things: is it still there?"
    );
}

#[test]
fn the_layers_and_the_readme_layout_match_the_tree() {
    let map = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let layout: Vec<&str> = readme
        .lines()
        .skip_while(|l| !l.starts_with("| folder |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .filter_map(|l| code_spans(l).first().copied())
        .collect();
    for path in &layout {
        assert!(
            root().join(path).exists(),
            "README layout: {path} does not exist"
        );
    }
    let folders = std::fs::read_dir(root().join("core/src")).unwrap();
    for entry in folders.map(|e| e.unwrap()) {
        if !entry.file_type().unwrap().is_dir() {
            continue;
        }
        let name = entry.file_name().to_string_lossy().into_owned();
        let line = format!("core/src/{name}/");
        assert!(
            layout.contains(&line.as_str()),
            "README layout lacks {line}"
        );
        assert!(
            map.contains(&format!("`{name}/`")),
            "docs/architecture.md's layers lack {name}/"
        );
    }
}
