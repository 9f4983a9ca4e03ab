//! A reader for Gmsh meshes: MSH 2.2 ASCII, MSH 4.1 ASCII and MSH 4.1 binary.
//!
//! Reads nodes, P1/P2 cells of the highest dimension present (lines, triangles or
//! tetrahedra), and physical groups: those of boundary elements become named boundary regions
//! (matched to cell facets by their vertices), those of cells become cell groups. Nodes are
//! numbered by increasing tag and cells by increasing element tag, so the same mesh in every
//! format reads identically. Every error names the file and the line (ASCII) or byte offset
//! (binary); counts in headers are checked against the data and never size an allocation.

use std::path::Path;

use std::collections::HashMap;

use crate::fem::mesh::{Mesh, MeshError};

mod build;
mod parser;

use build::build;
use parser::Parser;

/// Reads a mesh file and validates its geometry.
pub fn read(path: &Path) -> Result<Mesh, MeshError> {
    let file = path.display().to_string();
    let bytes = crate::input::read_bounded(path, crate::input::MAX_MESH_BYTES, "mesh file")
        .map_err(|e| MeshError::File { file: file.clone(), reason: e.to_string() })?;
    parse(&bytes, &file)
}

/// Parses the bytes of a mesh file named `file` (for messages).
pub fn parse(bytes: &[u8], file: &str) -> Result<Mesh, MeshError> {
    let raw = Parser::new(bytes, file).parse()?;
    build(raw, file)
}

/// Where something was read: a line (ASCII) or a byte offset (binary).
#[derive(Clone, Copy, Debug)]
pub(super) enum At {
    Line(usize),
    Byte(usize),
}

pub(super) fn err(file: &str, at: At, reason: impl Into<String>) -> MeshError {
    match at {
        At::Line(line) => MeshError::Line { file: file.to_string(), line, reason: reason.into() },
        At::Byte(offset) => MeshError::Byte { file: file.to_string(), offset, reason: reason.into() },
    }
}

pub(super) struct RawElement {
    pub(super) tag: u64,
    pub(super) kind: u32,
    pub(super) nodes: Vec<u64>,
    pub(super) physicals: Vec<i64>,
    pub(super) at: At,
}

#[derive(Default)]
pub(super) struct Raw {
    pub(super) nodes: Vec<(u64, [f64; 3], At)>,
    pub(super) elements: Vec<RawElement>,
    pub(super) names: HashMap<(u32, i64), String>,
    /// Elements of types we do not use: (type, tag, position).
    pub(super) skipped: Vec<(u32, u64, At)>,
}

/// Gmsh element types we read: (type, dimension, node count).
pub(super) fn element_info(kind: u32) -> Option<(u32, usize)> {
    Some(match kind {
        15 => (0, 1),
        1 => (1, 2),
        8 => (1, 3),
        2 => (2, 3),
        9 => (2, 6),
        4 => (3, 4),
        11 => (3, 10),
        _ => return None,
    })
}

/// Element types we skip: (dimension, node count, name), so that their data can be stepped
/// over and the skip reported.
pub(super) fn other_element_info(kind: u32) -> Option<(u32, usize, &'static str)> {
    Some(match kind {
        3 => (2, 4, "quadrangle"),
        5 => (3, 8, "hexahedron"),
        6 => (3, 6, "prism"),
        7 => (3, 5, "pyramid"),
        10 => (2, 9, "9-node quadrangle"),
        16 => (2, 8, "8-node quadrangle"),
        17 => (3, 20, "20-node hexahedron"),
        _ => return None,
    })
}

/// Node count of any element type we can step over.
pub(super) fn node_count(kind: u32) -> Option<usize> {
    element_info(kind).map(|(_, c)| c).or_else(|| other_element_info(kind).map(|(_, c, _)| c))
}

pub(super) fn truncate(s: &str) -> String {
    if s.chars().count() > 40 { format!("{}…", s.chars().take(40).collect::<String>()) } else { s.to_string() }
}
