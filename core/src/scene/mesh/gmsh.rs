//! Gmsh's `.msh` ASCII format, versions 2.2 and 4.1.
//!
//! Only the `$MeshFormat`, `$Nodes` and `$Elements` sections are read, one of each (a second is
//! refused); other sections are skipped.
//! Of the elements, 4-node tets (type 4) and 10-node tets (type 11, corners only) are kept; points,
//! lines, triangles and the rest are counted and ignored. Node tags may be any positive numbers;
//! elements refer to them by tag.

use super::text::{Line, Lines, check_distinct};
use super::{LoadReport, MeshError, TetMesh};
use glam::DVec3;
use std::collections::HashMap;
use std::path::Path;

/// Element type numbers of tets in Gmsh: 4 (linear) and 11 (quadratic, corners first).
const TET4: u32 = 4;
const TET10: u32 = 11;

#[derive(Clone, Copy, PartialEq)]
enum Version {
    V2,
    V4,
}

#[derive(Default)]
struct Nodes {
    positions: Vec<DVec3>,
    index_of_tag: HashMap<u64, u32>,
}

/// Loads a Gmsh ASCII `.msh` file of version 2.2 or 4.1.
pub fn load(path: &Path) -> Result<(TetMesh, LoadReport), MeshError> {
    let text = Lines::read(path)?;
    parse(path, &text)
}

/// Parses the text of a Gmsh ASCII `.msh` file read from `path`.
pub fn parse(path: &Path, text: &str) -> Result<(TetMesh, LoadReport), MeshError> {
    let mut lines = Lines::new(path, text, false);
    let version = read_format(&mut lines)?;
    let mut nodes: Option<Nodes> = None;
    let mut tets: Option<(Vec<[u32; 4]>, usize)> = None;
    while let Some(line) = lines.next_or_end() {
        let name = line.words[0];
        match name {
            "$Nodes" => {
                if nodes.is_some() {
                    return Err(line.error(
                        "a second $Nodes section: tetlab reads one (merge the sections in Gmsh)",
                    ));
                }
                nodes = Some(match version {
                    Version::V2 => nodes_v2(&mut lines)?,
                    Version::V4 => nodes_v4(&mut lines)?,
                });
                end_section(&mut lines, "$EndNodes")?;
            }
            "$Elements" => {
                if tets.is_some() {
                    return Err(line.error(
                        "a second $Elements section: tetlab reads one (merge the sections in Gmsh)",
                    ));
                }
                let Some(nodes) = &nodes else {
                    return Err(line.error("$Elements before $Nodes"));
                };
                tets = Some(match version {
                    Version::V2 => elements_v2(&mut lines, nodes)?,
                    Version::V4 => elements_v4(&mut lines, nodes)?,
                });
                end_section(&mut lines, "$EndElements")?;
            }
            _ if name.starts_with('$') && !name.starts_with("$End") => {
                skip_section(&mut lines, &line)?;
            }
            _ => {
                return Err(
                    line.error(format!("expected a section such as $Nodes, found '{name}'"))
                );
            }
        }
    }
    let nodes = nodes.ok_or_else(|| MeshError::whole_file(path, "no $Nodes section"))?;
    let (tets, ignored) =
        tets.ok_or_else(|| MeshError::whole_file(path, "no $Elements section"))?;
    if tets.is_empty() {
        return Err(MeshError::whole_file(
            path,
            "no tetrahedra (element type 4 or 11) in $Elements",
        ));
    }
    let (mesh, mut report) = TetMesh::new(nodes.positions, tets);
    report.ignored_elements = ignored;
    Ok((mesh, report))
}

fn read_format(lines: &mut Lines<'_>) -> Result<Version, MeshError> {
    let first = lines.next_line("$MeshFormat")?;
    if first.words[0] != "$MeshFormat" {
        return Err(first.error(format!(
            "expected $MeshFormat, found '{}': not a Gmsh .msh file",
            first.words[0]
        )));
    }
    let format = lines.next_line("<version> <file-type> <data-size>")?;
    format.expect_at_least(3, "<version> <file-type> <data-size>")?;
    let version = match format.words[0] {
        "2.2" | "2.1" | "2" | "2.0" => Version::V2,
        "4.1" => Version::V4,
        other => {
            return Err(format.error(format!(
                "MSH version {other} is not supported; expected 2.2 or 4.1"
            )));
        }
    };
    let file_type: u32 = format.integer(1, "file-type")?;
    if file_type != 0 {
        return Err(format.error("binary .msh is not supported; save the mesh as ASCII"));
    }
    end_section(lines, "$EndMeshFormat")?;
    Ok(version)
}

fn end_section(lines: &mut Lines<'_>, end: &str) -> Result<(), MeshError> {
    let line = lines.next_line(end)?;
    if line.words[0] == end {
        Ok(())
    } else {
        Err(line.error(format!(
            "expected {end}, found '{}' (more entries than the section declares?)",
            line.words[0]
        )))
    }
}

/// The sections tetlab reads.
const KNOWN: [&str; 3] = ["$MeshFormat", "$Nodes", "$Elements"];

/// Skips a section tetlab does not read, from its opening line `start` to its `$End…` line. A
/// name one letter away from a section tetlab reads is taken for a typing mistake, and a section
/// that is never closed is reported at its opening line.
fn skip_section(lines: &mut Lines<'_>, start: &Line<'_>) -> Result<(), MeshError> {
    let opening = start.words[0];
    if let Some(known) = KNOWN
        .into_iter()
        .find(|known| one_letter_apart(known, opening))
    {
        return Err(start.error(format!(
            "'{opening}' is not a section: did you mean {known}?"
        )));
    }
    let end = format!("$End{}", &opening[1..]);
    while let Some(line) = lines.next_or_end() {
        if line.words[0] == end {
            return Ok(());
        }
    }
    Err(start.error(format!("section {opening} is never closed by {end}")))
}

/// Whether `a` and `b` differ by exactly one letter changed, added or left out.
fn one_letter_apart(a: &str, b: &str) -> bool {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let (short, long) = if a.len() <= b.len() { (a, b) } else { (b, a) };
    match long.len() - short.len() {
        0 => short.iter().zip(&long).filter(|(x, y)| x != y).count() == 1,
        1 => (0..long.len()).any(|i| {
            let mut without = long.clone();
            without.remove(i);
            without == short
        }),
        _ => false,
    }
}

fn add_node(
    nodes: &mut Nodes,
    line: &Line<'_>,
    tag: u64,
    coordinates_at: usize,
) -> Result<(), MeshError> {
    let p = DVec3::new(
        line.coordinate(coordinates_at, "x")?,
        line.coordinate(coordinates_at + 1, "y")?,
        line.coordinate(coordinates_at + 2, "z")?,
    );
    let index = nodes.positions.len() as u32;
    if nodes.index_of_tag.insert(tag, index).is_some() {
        return Err(line.error(format!("node tag {tag} is defined twice")));
    }
    nodes.positions.push(p);
    Ok(())
}

fn count(line: &Line<'_>, i: usize, what: &str) -> Result<usize, MeshError> {
    line.integer(i, what)
}

fn nodes_v2(lines: &mut Lines<'_>) -> Result<Nodes, MeshError> {
    let header = lines.next_line("the number of nodes")?;
    let n = count(&header, 0, "number of nodes")?;
    let mut nodes = Nodes::default();
    for i in 0..n {
        let line = lines.next_line(&format!("node {} of {n}", i + 1))?;
        line.expect_at_least(4, "<tag> <x> <y> <z>")?;
        let tag = line.integer(0, "node tag")?;
        add_node(&mut nodes, &line, tag, 1)?;
    }
    Ok(nodes)
}

fn nodes_v4(lines: &mut Lines<'_>) -> Result<Nodes, MeshError> {
    let header = lines.next_line("<blocks> <nodes> <min tag> <max tag>")?;
    header.expect_at_least(4, "<blocks> <nodes> <min tag> <max tag>")?;
    let blocks = count(&header, 0, "number of entity blocks")?;
    let total = count(&header, 1, "number of nodes")?;
    let mut nodes = Nodes::default();
    for b in 0..blocks {
        let block = lines.next_line(&format!("node block {} of {blocks}", b + 1))?;
        block.expect_at_least(4, "<entity dim> <entity tag> <parametric> <nodes in block>")?;
        let in_block = count(&block, 3, "nodes in block")?;
        let mut tags = Vec::with_capacity(in_block.min(1 << 24));
        for _ in 0..in_block {
            let line = lines.next_line("a node tag")?;
            tags.push((line.integer::<u64>(0, "node tag")?, line.number));
        }
        for &(tag, _) in &tags {
            let line = lines.next_line(&format!("the coordinates of node {tag}"))?;
            line.expect_at_least(3, "<x> <y> <z>")?;
            add_node(&mut nodes, &line, tag, 0)?;
        }
    }
    if nodes.positions.len() != total {
        return Err(header.error(format!(
            "declares {total} nodes but its blocks hold {}",
            nodes.positions.len()
        )));
    }
    Ok(nodes)
}

/// Reads the corner tags of a tet element from `line` starting at word `first`, and maps them to
/// node indices.
fn tet_from(line: &Line<'_>, first: usize, nodes: &Nodes) -> Result<[u32; 4], MeshError> {
    let mut written = [0u64; 4];
    let mut tet = [0u32; 4];
    for k in 0..4 {
        let tag: u64 = line.integer(first + k, "node tag")?;
        tet[k] = *nodes
            .index_of_tag
            .get(&tag)
            .ok_or_else(|| line.error(format!("node tag {tag} is not defined in $Nodes")))?;
        written[k] = tag;
    }
    check_distinct(line, written)?;
    Ok(tet)
}

/// Adds the tet read on `line`, unless the mesh would then have more than
/// [`crate::input::limits::MAX_TETS`].
fn push_tet(tets: &mut Vec<[u32; 4]>, line: &Line<'_>, tet: [u32; 4]) -> Result<(), MeshError> {
    crate::input::limits::tet_count(tets.len() + 1).map_err(|e| line.error(e))?;
    tets.push(tet);
    Ok(())
}

fn elements_v2(lines: &mut Lines<'_>, nodes: &Nodes) -> Result<(Vec<[u32; 4]>, usize), MeshError> {
    let header = lines.next_line("the number of elements")?;
    let n = count(&header, 0, "number of elements")?;
    let (mut tets, mut ignored) = (Vec::new(), 0);
    for i in 0..n {
        let line = lines.next_line(&format!("element {} of {n}", i + 1))?;
        line.expect_at_least(3, "<tag> <type> <number of tags> …")?;
        let kind: u32 = line.integer(1, "element type")?;
        let tags = line.per_line(2, "number of tags")?;
        if kind == TET4 || kind == TET10 {
            let per = if kind == TET4 { 4 } else { 10 };
            line.expect_at_least(3 + tags + per, "a tet element's tags and nodes")?;
            push_tet(&mut tets, &line, tet_from(&line, 3 + tags, nodes)?)?;
        } else {
            ignored += 1;
        }
    }
    Ok((tets, ignored))
}

fn elements_v4(lines: &mut Lines<'_>, nodes: &Nodes) -> Result<(Vec<[u32; 4]>, usize), MeshError> {
    let header = lines.next_line("<blocks> <elements> <min tag> <max tag>")?;
    header.expect_at_least(4, "<blocks> <elements> <min tag> <max tag>")?;
    let blocks = count(&header, 0, "number of entity blocks")?;
    let total = count(&header, 1, "number of elements")?;
    let (mut tets, mut ignored, mut seen) = (Vec::new(), 0, 0);
    for b in 0..blocks {
        let block = lines.next_line(&format!("element block {} of {blocks}", b + 1))?;
        block.expect_at_least(
            4,
            "<entity dim> <entity tag> <element type> <elements in block>",
        )?;
        let kind: u32 = block.integer(2, "element type")?;
        let in_block = count(&block, 3, "elements in block")?;
        for _ in 0..in_block {
            let line = lines.next_line("an element")?;
            if kind == TET4 || kind == TET10 {
                let per = if kind == TET4 { 4 } else { 10 };
                line.expect_at_least(1 + per, "<tag> <nodes…>")?;
                push_tet(&mut tets, &line, tet_from(&line, 1, nodes)?)?;
            } else {
                ignored += 1;
            }
            seen += 1;
        }
    }
    if seen != total {
        return Err(header.error(format!(
            "declares {total} elements but its blocks hold {seen}"
        )));
    }
    Ok((tets, ignored))
}
