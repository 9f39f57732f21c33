//! TetGen `.node` and `.ele` text, as `tetlab` reads a mesh file: the input is the `.node` file,
//! a NUL byte, then the `.ele` file. Whatever the bytes, loading gives a mesh whose every index
//! is in range and every coordinate within the limits, or an error naming the file and a line
//! that exists; never a panic.

#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use tetlab_core::input::text_file::decode;
use tetlab_core::scene::Scene;
use tetlab_core::scene::mesh::{TetMesh, tetgen};

mod check;

fuzz_target!(|data: &[u8]| {
    let (node, ele) = match data.iter().position(|&b| b == 0) {
        Some(at) => (&data[..at], &data[at + 1..]),
        None => (data, &[][..]),
    };
    let (Ok(node), Ok(ele)) = (decode(node), decode(ele)) else {
        return;
    };
    let node_path = Path::new("fuzz.node");
    let ele_path = Path::new("fuzz.ele");
    let (positions, base) = match tetgen::parse_nodes(node_path, node) {
        Ok(parsed) => parsed,
        Err(e) => return check::error(&e, node),
    };
    let tets = match tetgen::parse_elements(ele_path, ele, positions.len(), base) {
        Ok(tets) => tets,
        Err(e) => return check::error(&e, ele),
    };
    let (mesh, report) = TetMesh::new(positions, tets);
    check::mesh(&mesh);
    check::scene(Scene::from_mesh("fuzz".into(), mesh, report));
});
