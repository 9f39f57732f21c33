//! The mesh loaders against the real files in `../shared/meshes/` (written by TetGen, Gmsh and
//! other tools), and against broken files, which must fail with the file and line named.

use std::path::{Path, PathBuf};
use tetlab_core::constraints::volume::signed_volume;
use tetlab_core::input::shared_meshes;
use tetlab_core::scene::mesh::{MeshError, TetMesh};

/// A reference mesh of `../shared/meshes`, loaded and checked; `None` when the folder is absent
/// (the test then skips, see [`shared_meshes::for_test`]).
fn load(name: &str) -> Option<TetMesh> {
    let path = shared_meshes::for_test(name)?;
    let (mesh, report) = TetMesh::load(&path).unwrap_or_else(|e| panic!("{e}"));
    println!(
        "{name}: {} nodes, {} tets, {:?}",
        mesh.positions.len(),
        mesh.tets.len(),
        report
    );
    assert!(
        (0..mesh.tets.len()).all(|t| signed_volume(&mesh.corners(t)) >= 0.0),
        "{name}: every tet positively oriented after loading"
    );
    Some(mesh)
}

#[test]
fn shared_meshes_have_the_counts_their_readme_states() {
    let Some(bunny) = load("bunny.node") else {
        return;
    };
    assert_eq!(
        (bunny.positions.len(), bunny.tets.len(), bunny.edges().len()),
        (333, 1351, 1907)
    );
    assert_eq!(
        bunny.surface_faces().len(),
        456,
        "bunny.face lists 456 surface triangles"
    );
    let bunny_from_ele = load("bunny.ele").expect("the folder is there");
    assert_eq!(bunny_from_ele, bunny);

    let armadillo = load("armadillo_4k.ele").expect("the folder is there");
    assert_eq!(
        (armadillo.positions.len(), armadillo.tets.len()),
        (1180, 3717)
    );

    let ball41 = load("ball_v41.msh").expect("the folder is there");
    let ball22 = load("ball_v22.msh").expect("the folder is there");
    assert_eq!((ball41.positions.len(), ball41.tets.len()), (470, 1812));
    assert_eq!(ball41, ball22, "the same mesh in Gmsh 4.1 and 2.2");

    let beam = load("beam_v41.msh").expect("the folder is there");
    assert_eq!((beam.positions.len(), beam.tets.len()), (423, 1208));
}

/// A scratch folder for one test's files.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tetlab-meshes-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

const NODE: &str = "# a unit tet\n4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
const ELE: &str = "1 4 0\n0 0 1 2 3\n";

fn tetgen_error(test: &str, node: &str, ele: &str) -> MeshError {
    let dir = scratch(test);
    write(&dir, "m.ele", ele);
    let path = write(&dir, "m.node", node);
    TetMesh::load(&path).expect_err("the file is broken")
}

fn gmsh_error(test: &str, text: &str) -> MeshError {
    let path = write(&scratch(test), "m.msh", text);
    TetMesh::load(&path).expect_err("the file is broken")
}

#[track_caller]
fn assert_error(error: &MeshError, file: &str, line: Option<usize>, says: &str) {
    let text = error.to_string();
    assert!(error.path.ends_with(file), "{text}");
    assert_eq!(error.line, line, "{text}");
    assert!(text.contains(says), "{text:?} should say {says:?}");
    if let Some(line) = line {
        assert!(
            text.contains(&format!("{file}:{line}: ")),
            "file:line in {text}"
        );
    }
}

#[test]
fn tetgen_files_may_be_one_based_with_comments_attributes_markers_and_quadratic_tets() {
    let dir = scratch("tetgen-variants");
    write(
        &dir,
        "m.node",
        "4 3 1 1 # header\n\n1 0 0 0 7.5 1\n2 1 0 0 7.5 1\n3 0 1 0 7.5 0 # ok\n4 0 0 1 7.5 1\n",
    );
    write(&dir, "m.ele", "1 10 1\n1 1 2 4 3 1 1 1 1 1 1 42\n");
    let (mesh, report) = TetMesh::load(&dir.join("m.ele")).unwrap();
    assert_eq!((mesh.positions.len(), mesh.tets.len()), (4, 1));
    assert_eq!(report.reoriented_tets, 1, "1 2 4 3 is negatively oriented");
    assert!(signed_volume(&mesh.corners(0)) > 0.0);
}

#[test]
fn unused_nodes_are_dropped_and_the_tets_renumbered() {
    let dir = scratch("unused");
    write(
        &dir,
        "m.node",
        "5 3 0 0\n0 9 9 9\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n",
    );
    write(&dir, "m.ele", "1 4 0\n0 1 2 3 4\n");
    let (mesh, report) = TetMesh::load(&dir.join("m.node")).unwrap();
    assert_eq!(report.unused_nodes, 1);
    assert_eq!(mesh.tets, vec![[0, 1, 2, 3]]);
    assert_eq!(mesh.positions[0], glam::DVec3::ZERO);
}

#[test]
fn broken_tetgen_files_name_the_file_and_line() {
    let e = tetgen_error("dim", "4 2 0 0\n", ELE);
    assert_error(&e, "m.node", Some(1), "dimension is 2");
    let e = tetgen_error(
        "nan",
        "# c\n4 3 0 0\n0 0 0 0\n1 NaN 0 0\n2 0 1 0\n3 0 0 1\n",
        ELE,
    );
    assert_error(&e, "m.node", Some(4), "'NaN' is not a finite number");
    let e = tetgen_error(
        "word",
        "4 3 0 0\n0 0 0 0\n1 1 zero 0\n2 0 1 0\n3 0 0 1\n",
        ELE,
    );
    assert_error(&e, "m.node", Some(3), "'zero' is not a number");
    let e = tetgen_error(
        "short-line",
        "4 3 0 0\n0 0 0 0\n1 1 0\n2 0 1 0\n3 0 0 1\n",
        ELE,
    );
    assert_error(&e, "m.node", Some(3), "expected <index> <x> <y> <z>");
    let e = tetgen_error("truncated", "4 3 0 0\n0 0 0 0\n1 1 0 0\n", ELE);
    assert_error(&e, "m.node", Some(4), "file ends; expected point 3 of 4");
    let e = tetgen_error(
        "numbering",
        "4 3 0 0\n0 0 0 0\n2 1 0 0\n2 0 1 0\n3 0 0 1\n",
        ELE,
    );
    assert_error(&e, "m.node", Some(3), "expected 1");
    let e = tetgen_error("extra", &format!("{NODE}4 1 1 1\n"), ELE);
    assert_error(&e, "m.node", Some(7), "more points than the 4");
    let e = tetgen_error("range", NODE, "1 4 0\n0 0 1 2 4\n");
    assert_error(&e, "m.ele", Some(2), "node 4 does not exist");
    let e = tetgen_error("twice", NODE, "1 4 0\n0 0 1 2 2\n");
    assert_error(&e, "m.ele", Some(2), "uses node 2 twice");
    let e = tetgen_error("per-tet", NODE, "1 3 0\n0 0 1 2\n");
    assert_error(&e, "m.ele", Some(1), "nodes per tet is 3");
    let e = tetgen_error("negative", NODE, "1 4 0\n0 0 -1 2 3\n");
    assert_error(&e, "m.ele", Some(2), "'-1' is not a non-negative integer");
    let e = tetgen_error("ele-truncated", NODE, "2 4 0\n0 0 1 2 3\n");
    assert_error(&e, "m.ele", Some(3), "file ends; expected tet 2 of 2");
    let e = tetgen_error("empty", "", ELE);
    assert_error(&e, "m.node", Some(1), "file ends; expected the header");

    let dir = scratch("missing-ele");
    let path = write(&dir, "m.node", NODE);
    let e = TetMesh::load(&path).unwrap_err();
    assert_error(&e, "m.ele", None, "cannot read");
}

/// The defects a fuzzing pass found in the loaders (issue 13), each refused where it is written.
#[test]
fn headers_coordinates_and_sections_out_of_bounds_are_refused_at_their_line() {
    // A count of attributes that wraps `4 + attributes` in release (and panicked in debug).
    let huge = "18446744073709551615";
    let e = tetgen_error("attributes", &format!("5 3 {huge} 0\n"), ELE);
    assert_error(
        &e,
        "m.node",
        Some(1),
        "more than the 65536 values a line may hold",
    );
    let e = tetgen_error("ele-attributes", NODE, &format!("2 4 {huge}\n"));
    assert_error(
        &e,
        "m.ele",
        Some(1),
        "more than the 65536 values a line may hold",
    );
    let e = tetgen_error("markers", "4 3 0 99999999999\n", ELE);
    assert_error(&e, "m.node", Some(1), "boundary markers");
    let e = tetgen_error("tets", NODE, "99999999999 4 0\n");
    assert_error(
        &e,
        "m.ele",
        Some(1),
        "more than the 16777216 tetlab simulates",
    );
    // Coordinates whose fourth power overflows f32.
    let e = tetgen_error("far", &NODE.replace("3 0 0 1", "3 0 0 1e31"), ELE);
    assert_error(&e, "m.node", Some(6), "z: 1e31 is beyond ±1e6");
    let e = gmsh_error("far", &MSH22.replace("3 0 1 0", "3 0 -2e6 0"));
    assert_error(&e, "m.msh", Some(8), "y: -2e6 is beyond ±1e6");
    // A second $Elements section no longer replaces the first.
    let twice = MSH22.replace(
        "$EndElements\n",
        "$EndElements\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n",
    );
    let e = gmsh_error("elements-twice", &twice);
    assert_error(&e, "m.msh", Some(16), "a second $Elements section");
    // A misspelt section is reported where it is, not at the end of the file.
    let e = gmsh_error("nodez", &MSH22.replace("$Nodes\n", "$Nodez\n"));
    assert_error(
        &e,
        "m.msh",
        Some(4),
        "'$Nodez' is not a section: did you mean $Nodes?",
    );
    let e = gmsh_error(
        "unclosed",
        &MSH22.replace("$Nodes\n", "$Comments\nhello\n$Nodes\n"),
    );
    assert_error(
        &e,
        "m.msh",
        Some(4),
        "section $Comments is never closed by $EndComments",
    );
    let e = gmsh_error(
        "v2-tags",
        &MSH22.replace("2 4 2 0 1", &format!("2 4 {huge} 0 1")),
    );
    assert_error(&e, "m.msh", Some(14), "number of tags");
}

/// A byte-order mark some editors write first is skipped, never quoted in an error.
#[test]
fn a_byte_order_mark_is_skipped() {
    let dir = scratch("bom");
    write(&dir, "m.node", &format!("\u{feff}{NODE}"));
    write(&dir, "m.ele", &format!("\u{feff}{ELE}"));
    let (mesh, _) = TetMesh::load(&dir.join("m.node")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(mesh.tets.len(), 1);
    let e = gmsh_error("bom", "\u{feff}$MeshFormat\n9.9 0 8\n");
    assert_error(&e, "m.msh", Some(2), "MSH version 9.9");
    let e = gmsh_error("bom-word", "\u{feff}solid\n");
    assert!(!e.to_string().contains('\u{feff}'), "{e}");
    assert_error(&e, "m.msh", Some(1), "found 'solid'");
}

const MSH22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n2\n1 2 2 0 1 1 2 3\n2 4 2 0 1 1 2 3 4\n$EndElements\n";
const MSH41: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";

#[test]
fn small_gmsh_files_of_both_versions_load() {
    for (name, text) in [("v22", MSH22), ("v41", MSH41)] {
        let path = write(&scratch(name), "m.msh", text);
        let (mesh, report) = TetMesh::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((mesh.positions.len(), mesh.tets.len()), (4, 1), "{name}");
        assert_eq!(report.ignored_elements, if name == "v22" { 1 } else { 0 });
    }
}

#[test]
fn broken_gmsh_files_name_the_file_and_line() {
    let e = gmsh_error("not-msh", "solid cube\n");
    assert_error(&e, "m.msh", Some(1), "not a Gmsh .msh file");
    let e = gmsh_error("binary", &MSH41.replace("4.1 0 8", "4.1 1 8"));
    assert_error(&e, "m.msh", Some(2), "binary .msh is not supported");
    let e = gmsh_error("version", &MSH41.replace("4.1 0 8", "3.0 0 8"));
    assert_error(&e, "m.msh", Some(2), "MSH version 3.0 is not supported");
    let e = gmsh_error(
        "undefined-node",
        &MSH22.replace("1 1 2 3 4\n", "1 1 2 3 9\n"),
    );
    assert_error(&e, "m.msh", Some(14), "node tag 9 is not defined");
    let e = gmsh_error("nan", &MSH22.replace("3 0 1 0", "3 0 inf 0"));
    assert_error(&e, "m.msh", Some(8), "'inf' is not a finite number");
    let cut: String = MSH41.lines().take(12).map(|l| format!("{l}\n")).collect();
    let e = gmsh_error("truncated", &cut);
    assert_error(
        &e,
        "m.msh",
        Some(13),
        "file ends; expected the coordinates of node 3",
    );
    let e = gmsh_error("count", &MSH41.replace("1 4 1 4\n", "1 5 1 4\n"));
    assert_error(
        &e,
        "m.msh",
        Some(5),
        "declares 5 nodes but its blocks hold 4",
    );
    let e = gmsh_error("extra", &MSH22.replace("4\n1 0 0 0", "3\n1 0 0 0"));
    assert_error(&e, "m.msh", Some(9), "expected $EndNodes");
    let e = gmsh_error(
        "no-tets",
        &MSH22.replace(
            "2\n1 2 2 0 1 1 2 3\n2 4 2 0 1 1 2 3 4\n",
            "1\n1 2 2 0 1 1 2 3\n",
        ),
    );
    assert_error(&e, "m.msh", None, "no tetrahedra");
    let e = gmsh_error(
        "short-tet",
        &MSH22.replace("2 4 2 0 1 1 2 3 4", "2 4 2 0 1 1 2 3"),
    );
    assert_error(
        &e,
        "m.msh",
        Some(14),
        "expected a tet element's tags and nodes",
    );

    let path = scratch("utf8").join("m.msh");
    std::fs::write(&path, b"$MeshFormat\n\xff\xfe\n").unwrap();
    assert_error(
        &TetMesh::load(&path).unwrap_err(),
        "m.msh",
        Some(2),
        "not text",
    );

    let path = write(&scratch("extension"), "m.stl", "solid");
    assert_error(
        &TetMesh::load(&path).unwrap_err(),
        "m.stl",
        None,
        "unknown mesh format",
    );
}

#[test]
fn built_in_scenes_are_well_formed() {
    use tetlab_core::scene::{Builtin, Scene};
    for builtin in Builtin::ALL {
        for resolution in [1, 2, 4] {
            let scene = Scene::builtin(builtin, resolution).unwrap();
            let mesh = &scene.mesh;
            let (cleaned, report) = TetMesh::new(mesh.positions.clone(), mesh.tets.clone());
            assert_eq!(
                &cleaned, mesh,
                "{builtin:?}: no unused node, every tet positive"
            );
            assert_eq!(report.degenerate_tets, 0, "{builtin:?} {resolution}");
            let lowest = mesh
                .positions
                .iter()
                .map(|p| p.y)
                .fold(f64::INFINITY, f64::min);
            assert!(lowest >= 0.0, "{builtin:?} rests on or above the ground");
            // A closed surface: every edge of the boundary is shared by exactly two faces.
            let mut edges = std::collections::HashMap::new();
            for f in mesh.surface_faces() {
                for (a, b) in [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])] {
                    *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
            assert!(
                edges.values().all(|&n| n == 2),
                "{builtin:?}: surface is closed"
            );
        }
    }
    let cube = Scene::builtin(Builtin::Cube, 4).unwrap();
    assert_eq!(
        (cube.mesh.positions.len(), cube.mesh.tets.len()),
        (125, 384)
    );
    let total: f64 = (0..cube.mesh.tets.len())
        .map(|t| signed_volume(&cube.mesh.corners(t)))
        .sum();
    assert!(
        (total - 1.0).abs() < 1e-12,
        "the unit cube's tets fill it exactly"
    );
    assert!(Scene::builtin(Builtin::Cube, 0).is_err());
    assert!(
        Scene::from_spec("no-such-scene", 4)
            .unwrap_err()
            .to_string()
            .contains("neither a built-in")
    );
}

#[test]
fn perturbations_do_what_they_say() {
    use tetlab_core::scene::{Builtin, Perturbation, Scene};
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let mesh = &scene.mesh;
    let volumes = |p: &[glam::DVec3]| -> Vec<f64> {
        mesh.tets
            .iter()
            .map(|t| signed_volume(&t.map(|i| p[i as usize])))
            .collect()
    };
    let lengths = |p: &[glam::DVec3]| -> Vec<f64> {
        mesh.edges()
            .iter()
            .map(|[a, b]| p[*a as usize].distance(p[*b as usize]))
            .collect()
    };
    let rest_lengths = lengths(&mesh.positions);
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);

    let mut p = mesh.positions.clone();
    Perturbation::Mirror.apply(&mut p, mesh);
    assert!(
        volumes(&p).iter().all(|&v| v < 0.0),
        "mirror inverts every tet"
    );
    assert!(
        close(&lengths(&p), &rest_lengths),
        "mirror keeps every edge length"
    );

    let mut p = mesh.positions.clone();
    Perturbation::Invert.apply(&mut p, mesh);
    assert!(volumes(&p)[0] < 0.0, "invert inverts tet 0");
    let t0 = mesh.tets[0];
    for (a, b) in [(0, 1), (0, 2), (0, 3)] {
        let (i, j) = (t0[a] as usize, t0[b] as usize);
        assert!(
            (p[i].distance(p[j]) - mesh.positions[i].distance(mesh.positions[j])).abs() < 1e-12
        );
    }

    let mut p = mesh.positions.clone();
    Perturbation::Flatten.apply(&mut p, mesh);
    assert!(
        volumes(&p).iter().all(|&v| v == 0.0),
        "flatten makes every tet flat"
    );

    let (mut a, mut b, mut c) = (
        mesh.positions.clone(),
        mesh.positions.clone(),
        mesh.positions.clone(),
    );
    Perturbation::Scramble(3).apply(&mut a, mesh);
    Perturbation::Scramble(3).apply(&mut b, mesh);
    Perturbation::Scramble(4).apply(&mut c, mesh);
    assert_eq!(a, b, "the same seed scrambles the same way");
    assert_ne!(a, c);

    for text in ["invert", "mirror", "flatten", "scramble:42"] {
        assert_eq!(Perturbation::parse(text).unwrap().to_string(), text);
    }
    assert!(
        Perturbation::parse("scramble:x")
            .unwrap_err()
            .contains("not a seed")
    );
    assert!(
        Perturbation::parse("twist")
            .unwrap_err()
            .contains("not a perturbation")
    );
}
