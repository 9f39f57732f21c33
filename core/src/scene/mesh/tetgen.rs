//! TetGen's `.node` / `.ele` text format.
//!
//! `.node`: a header `<points> <dimension = 3> <attributes> <boundary markers 0|1>`, then one line
//! per point `<index> <x> <y> <z> [attributes…] [marker]`. `.ele`: a header
//! `<tets> <nodes per tet = 4|10> <attributes>`, then `<index> <n1> … <nk> [attributes…]`; of a
//! 10-node tet the first four (the corners) are used. `#` starts a comment. Points are numbered
//! from 0 or from 1, as the first point says, and the tets use the same numbering.

use super::text::{Line, Lines, check_distinct};
use super::{LoadReport, MeshError, TetMesh};
use glam::DVec3;
use std::path::Path;

/// Loads `stem.node` and `stem.ele`, given either of the two paths.
pub(super) fn load(path: &Path) -> Result<(TetMesh, LoadReport), MeshError> {
    let node_path = path.with_extension("node");
    let ele_path = path.with_extension("ele");
    let node_text = Lines::read(&node_path)?;
    let ele_text = Lines::read(&ele_path)?;
    let (positions, base) = parse_nodes(&node_path, &node_text)?;
    let tets = parse_elements(&ele_path, &ele_text, positions.len(), base)?;
    Ok(TetMesh::new(positions, tets))
}

/// The points of a `.node` file and the number of its first point (0 or 1).
pub fn parse_nodes(path: &Path, text: &str) -> Result<(Vec<DVec3>, u64), MeshError> {
    let mut lines = Lines::new(path, text, true);
    let header = lines.next_line("the header: <points> 3 <attributes> <markers>")?;
    header.expect_at_least(2, "<points> <dimension>")?;
    let count: usize = header.integer(0, "number of points")?;
    let dimension: usize = header.integer(1, "dimension")?;
    if dimension != 3 {
        return Err(header.error(format!("dimension is {dimension}; tet meshes need 3")));
    }
    let attributes = optional(&header, 2, "number of attributes")?;
    let markers = optional(&header, 3, "number of boundary markers")?;
    if markers > 1 {
        return Err(header.error(format!("boundary markers must be 0 or 1, found {markers}")));
    }
    if count == 0 {
        return Err(header.error("the file declares 0 points"));
    }
    let mut positions = Vec::with_capacity(count.min(1 << 24));
    let mut base = 0;
    for i in 0..count {
        let line = lines.next_line(&format!("point {} of {count}", i + 1))?;
        line.expect_at_least(
            4 + attributes + markers,
            "<index> <x> <y> <z> [attributes] [marker]",
        )?;
        let index: u64 = line.integer(0, "point index")?;
        if i == 0 {
            if index > 1 {
                return Err(line.error(format!(
                    "the first point is numbered {index}; expected 0 or 1"
                )));
            }
            base = index;
        } else if index != base + i as u64 {
            return Err(line.error(format!(
                "point numbered {index}; expected {} (points are numbered consecutively)",
                base + i as u64
            )));
        }
        positions.push(DVec3::new(
            line.coordinate(1, "x")?,
            line.coordinate(2, "y")?,
            line.coordinate(3, "z")?,
        ));
    }
    reject_extra(&mut lines, count, "points")?;
    Ok((positions, base))
}

/// The tets of an `.ele` file as 0-based indices into `node_count` points numbered from `base`.
pub fn parse_elements(
    path: &Path,
    text: &str,
    node_count: usize,
    base: u64,
) -> Result<Vec<[u32; 4]>, MeshError> {
    let mut lines = Lines::new(path, text, true);
    let header = lines.next_line("the header: <tets> <nodes per tet> <attributes>")?;
    header.expect_at_least(2, "<tets> <nodes per tet>")?;
    let count = header.tet_count(0, "number of tets")?;
    let per_tet: usize = header.integer(1, "nodes per tet")?;
    if per_tet != 4 && per_tet != 10 {
        return Err(header.error(format!("nodes per tet is {per_tet}; expected 4 or 10")));
    }
    let attributes = optional(&header, 2, "number of attributes")?;
    if count == 0 {
        return Err(header.error("the file declares 0 tets"));
    }
    let mut tets = Vec::with_capacity(count.min(1 << 24));
    for i in 0..count {
        let line = lines.next_line(&format!("tet {} of {count}", i + 1))?;
        line.expect_at_least(1 + per_tet + attributes, "<index> <nodes…> [attributes]")?;
        let index: u64 = line.integer(0, "tet index")?;
        if index != base + i as u64 {
            return Err(line.error(format!(
                "tet numbered {index}; expected {} (tets are numbered like the points, from {base})",
                base + i as u64
            )));
        }
        let mut written = [0u64; 4];
        for (k, slot) in written.iter_mut().enumerate() {
            let node: u64 = line.integer(k + 1, "node number")?;
            if node < base || node - base >= node_count as u64 {
                return Err(line.error(format!(
                    "node {node} does not exist: the .node file has points {base}..{}",
                    base + node_count as u64 - 1
                )));
            }
            *slot = node;
        }
        check_distinct(&line, written)?;
        tets.push(written.map(|n| (n - base) as u32));
    }
    reject_extra(&mut lines, count, "tets")?;
    Ok(tets)
}

/// Header word `i`, a count of values per line, or 0 when the header ends before it.
fn optional(header: &Line<'_>, i: usize, what: &str) -> Result<usize, MeshError> {
    if header.words.len() > i {
        header.per_line(i, what)
    } else {
        Ok(0)
    }
}

fn reject_extra(lines: &mut Lines<'_>, count: usize, what: &str) -> Result<(), MeshError> {
    match lines.next_or_end() {
        Some(line) => Err(line.error(format!("more {what} than the {count} the header declares"))),
        None => Ok(()),
    }
}
