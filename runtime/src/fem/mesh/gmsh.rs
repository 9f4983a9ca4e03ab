//! A reader for Gmsh meshes: MSH 2.2 ASCII, MSH 4.1 ASCII and MSH 4.1 binary.
//!
//! Reads nodes, P1/P2 cells of the highest dimension present (lines, triangles or
//! tetrahedra), and physical groups: those of boundary elements become named boundary regions
//! (matched to cell facets by their vertices), those of cells become cell groups. Nodes are
//! numbered by increasing tag and cells by increasing element tag, so the same mesh in every
//! format reads identically. Every error names the file and the line (ASCII) or byte offset
//! (binary); counts in headers are checked against the data and never size an allocation.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use super::boundary::facet_key;
use super::{Facet, Mesh, MeshError, Region};
use crate::fem::element::ElementKind;

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
enum At {
    Line(usize),
    Byte(usize),
}

fn err(file: &str, at: At, reason: impl Into<String>) -> MeshError {
    match at {
        At::Line(line) => MeshError::Line { file: file.to_string(), line, reason: reason.into() },
        At::Byte(offset) => MeshError::Byte { file: file.to_string(), offset, reason: reason.into() },
    }
}

struct RawElement {
    tag: u64,
    kind: u32,
    nodes: Vec<u64>,
    physicals: Vec<i64>,
    at: At,
}

#[derive(Default)]
struct Raw {
    nodes: Vec<(u64, [f64; 3], At)>,
    elements: Vec<RawElement>,
    names: HashMap<(u32, i64), String>,
    /// Elements of types we do not use: (type, tag, position).
    skipped: Vec<(u32, u64, At)>,
}

/// Gmsh element types we read: (type, dimension, node count).
fn element_info(kind: u32) -> Option<(u32, usize)> {
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
fn other_element_info(kind: u32) -> Option<(u32, usize, &'static str)> {
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
fn node_count(kind: u32) -> Option<usize> {
    element_info(kind).map(|(_, c)| c).or_else(|| other_element_info(kind).map(|(_, c, _)| c))
}

struct Parser<'a> {
    bytes: &'a [u8],
    file: &'a str,
    pos: usize,
    line: usize,
    binary: bool,
    little_endian: bool,
    version: u32,
}

impl<'a> Parser<'a> {
    fn new(bytes: &'a [u8], file: &'a str) -> Self {
        Parser { bytes, file, pos: 0, line: 1, binary: false, little_endian: true, version: 0 }
    }

    fn at(&self) -> At {
        if self.binary { At::Byte(self.pos) } else { At::Line(self.line) }
    }

    /// The position of the next token (ASCII: after skipping whitespace, so on its line).
    fn here(&mut self) -> At {
        if !self.binary {
            while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
                if self.bytes[self.pos] == b'\n' {
                    self.line += 1;
                }
                self.pos += 1;
            }
        }
        self.at()
    }

    fn error(&self, reason: impl Into<String>) -> MeshError {
        err(self.file, self.at(), reason)
    }

    fn line_error(&self, reason: impl Into<String>) -> MeshError {
        err(self.file, At::Line(self.line), reason)
    }

    /// The next line (without its end), or None at the end of the file.
    fn next_line(&mut self) -> Option<&'a str> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let rest = &self.bytes[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let line = &rest[..end];
        self.pos += (end + 1).min(rest.len());
        self.line += 1;
        let text = std::str::from_utf8(line).unwrap_or("\u{fffd}");
        Some(text.trim_end_matches('\r'))
    }

    /// The next whitespace-separated token (ASCII sections).
    fn token(&mut self, what: &str) -> Result<&'a str, MeshError> {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            if self.bytes[self.pos] == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        if self.pos >= self.bytes.len() {
            return Err(self.line_error(format!("unexpected end of file: expected {what}")));
        }
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let bytes: &'a [u8] = self.bytes;
        let tok = std::str::from_utf8(&bytes[start..self.pos])
            .map_err(|_| self.line_error(format!("expected {what}, found non-UTF-8 bytes")))?;
        if tok.starts_with('$') {
            return Err(self.line_error(format!("expected {what}, found `{tok}` (a count does not match the data)")));
        }
        Ok(tok)
    }

    fn uint(&mut self, what: &str) -> Result<u64, MeshError> {
        if self.binary {
            return self.bin_u64(what);
        }
        let t = self.token(what)?;
        t.parse::<u64>().map_err(|_| self.line_error(format!("expected {what} (a non-negative integer), found `{t}`")))
    }

    fn int(&mut self, what: &str) -> Result<i64, MeshError> {
        if self.binary {
            return self.bin_i32(what).map(i64::from);
        }
        let t = self.token(what)?;
        t.parse::<i64>().map_err(|_| self.line_error(format!("expected {what} (an integer), found `{t}`")))
    }

    /// An int in binary files (4 bytes), an integer token in ASCII.
    fn small(&mut self, what: &str) -> Result<u64, MeshError> {
        if self.binary {
            let v = self.bin_i32(what)?;
            return u64::try_from(v).map_err(|_| self.error(format!("{what} is negative ({v})")));
        }
        self.uint(what)
    }

    fn float(&mut self, what: &str) -> Result<f64, MeshError> {
        let at = self.here();
        let v = if self.binary {
            let b = self.take(8, what)?;
            let a: [u8; 8] = b.try_into().expect("8 bytes");
            if self.little_endian { f64::from_le_bytes(a) } else { f64::from_be_bytes(a) }
        } else {
            let t = self.token(what)?;
            t.parse::<f64>().map_err(|_| self.line_error(format!("expected {what} (a number), found `{t}`")))?
        };
        if !v.is_finite() {
            return Err(err(self.file, at, format!("{what} is not finite ({v})")));
        }
        Ok(v)
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], MeshError> {
        if self.bytes.len() - self.pos < n {
            return Err(self.error(format!("unexpected end of file: expected {what} ({n} bytes)")));
        }
        let b = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(b)
    }

    fn bin_i32(&mut self, what: &str) -> Result<i32, MeshError> {
        let a: [u8; 4] = self.take(4, what)?.try_into().expect("4 bytes");
        Ok(if self.little_endian { i32::from_le_bytes(a) } else { i32::from_be_bytes(a) })
    }

    fn bin_u64(&mut self, what: &str) -> Result<u64, MeshError> {
        let a: [u8; 8] = self.take(8, what)?.try_into().expect("8 bytes");
        Ok(if self.little_endian { u64::from_le_bytes(a) } else { u64::from_be_bytes(a) })
    }

    /// Expects the `$EndName` line that closes a section.
    fn end_section(&mut self, name: &str) -> Result<(), MeshError> {
        if self.binary {
            // Binary data is followed by a newline before the end marker.
            while self.pos < self.bytes.len() && (self.bytes[self.pos] == b'\n' || self.bytes[self.pos] == b'\r') {
                self.pos += 1;
            }
            let want = format!("$End{name}");
            if !self.bytes[self.pos..].starts_with(want.as_bytes()) {
                return Err(
                    self.error(format!("expected `{want}` (the data of ${name} is longer than its counts say)"))
                );
            }
            self.pos += want.len();
            if self.pos < self.bytes.len() && self.bytes[self.pos] == b'\r' {
                self.pos += 1;
            }
            if self.pos < self.bytes.len() && self.bytes[self.pos] == b'\n' {
                self.pos += 1;
            }
            return Ok(());
        }
        // Skip the rest of the current line, then expect the marker.
        loop {
            let line_no = self.line;
            match self.next_line() {
                None => return Err(self.line_error(format!("unexpected end of file: `$End{name}` is missing"))),
                Some(l) if l.trim().is_empty() => continue,
                Some(l) if l.trim() == format!("$End{name}") => return Ok(()),
                Some(l) => {
                    return Err(err(
                        self.file,
                        At::Line(line_no),
                        format!(
                            "expected `$End{name}`, found `{}` (the data of ${name} is longer than its counts say)",
                            truncate(l)
                        ),
                    ));
                }
            }
        }
    }

    fn parse(mut self) -> Result<Raw, MeshError> {
        let mut raw = Raw::default();
        let mut seen_format = false;
        let mut entity_physicals: HashMap<(u32, i64), Vec<i64>> = HashMap::new();
        let mut once: Vec<(String, usize)> = Vec::new();
        loop {
            let line_no = self.line;
            let Some(line) = self.next_line() else { break };
            let name = line.trim();
            if name.is_empty() {
                continue;
            }
            let Some(section) = name.strip_prefix('$') else {
                return Err(err(
                    self.file,
                    At::Line(line_no),
                    format!("expected a section such as `$Nodes`, found `{}`", truncate(name)),
                ));
            };
            if !seen_format && section != "MeshFormat" {
                return Err(err(
                    self.file,
                    At::Line(line_no),
                    "not a Gmsh mesh: the file must start with `$MeshFormat`",
                ));
            }
            // Gmsh writes each of these once; a second one (two files concatenated, an edit
            // gone wrong) would silently merge or replace the first.
            if ["MeshFormat", "PhysicalNames", "Entities", "Nodes", "Elements"].contains(&section) {
                if let Some((_, first)) = once.iter().find(|(s, _)| *s == section) {
                    return Err(err(
                        self.file,
                        At::Line(line_no),
                        format!("a second `${section}` section (the first is at line {first})"),
                    ));
                }
                once.push((section.to_string(), line_no));
            }
            match section {
                "MeshFormat" => {
                    self.mesh_format()?;
                    seen_format = true;
                }
                "PhysicalNames" => {
                    // ASCII even in binary files.
                    let binary = std::mem::replace(&mut self.binary, false);
                    let result = self.physical_names(&mut raw).and_then(|()| self.end_section("PhysicalNames"));
                    self.binary = binary;
                    result?;
                }
                "Entities" if self.version == 4 => {
                    entity_physicals = self.entities()?;
                    self.end_section("Entities")?;
                }
                "Nodes" => {
                    if self.version == 4 {
                        self.nodes4(&mut raw)?
                    } else {
                        self.nodes2(&mut raw)?
                    }
                    self.end_section("Nodes")?;
                }
                "Elements" => {
                    if self.version == 4 {
                        self.elements4(&mut raw, &entity_physicals)?
                    } else {
                        self.elements2(&mut raw)?
                    }
                    self.end_section("Elements")?;
                }
                other => {
                    if other.starts_with("End") {
                        return Err(err(self.file, At::Line(line_no), format!("`${other}` without its section")));
                    }
                    self.skip_section(other, line_no)?;
                }
            }
        }
        if !seen_format {
            return Err(err(self.file, At::Line(1), "not a Gmsh mesh: the file is empty or has no `$MeshFormat`"));
        }
        if raw.nodes.is_empty() {
            return Err(err(self.file, At::Line(self.line), "the file has no `$Nodes` section (or it is empty)"));
        }
        Ok(raw)
    }

    /// Skips an unknown section (`$Periodic`, `$NodeData`, ...) up to its end marker.
    fn skip_section(&mut self, name: &str, start: usize) -> Result<(), MeshError> {
        let end = format!("$End{name}");
        let marker = end.as_bytes();
        match self.bytes[self.pos..].windows(marker.len()).position(|w| w == marker) {
            Some(i) => {
                let skipped = &self.bytes[self.pos..self.pos + i + marker.len()];
                self.line += skipped.iter().filter(|&&b| b == b'\n').count();
                self.pos += i + marker.len();
                self.next_line();
                Ok(())
            }
            None => Err(err(self.file, At::Line(start), format!("section `${name}` has no `{end}`"))),
        }
    }

    fn mesh_format(&mut self) -> Result<(), MeshError> {
        let line_no = self.line;
        let line = self.next_line().ok_or_else(|| self.line_error("unexpected end of file in `$MeshFormat`"))?;
        let parts: Vec<&str> = line.split_whitespace().collect();
        let [version, file_type, data_size] = parts[..] else {
            return Err(err(
                self.file,
                At::Line(line_no),
                format!("expected `version file-type data-size`, found `{}`", truncate(line)),
            ));
        };
        self.version = match version {
            "2.2" => 2,
            "4.1" => 4,
            v => {
                return Err(err(
                    self.file,
                    At::Line(line_no),
                    format!("unsupported MSH version {v} (this reader reads 2.2 and 4.1)"),
                ));
            }
        };
        self.binary = match file_type {
            "0" => false,
            "1" => true,
            t => {
                return Err(err(
                    self.file,
                    At::Line(line_no),
                    format!("file-type must be 0 (ASCII) or 1 (binary), not `{t}`"),
                ));
            }
        };
        if self.binary && self.version == 2 {
            return Err(err(
                self.file,
                At::Line(line_no),
                "MSH 2.2 binary files are not supported (save as 4.1, or 2.2 ASCII)",
            ));
        }
        if data_size != "8" {
            return Err(err(self.file, At::Line(line_no), format!("data-size must be 8, not `{data_size}`")));
        }
        if self.binary {
            let at = self.at();
            let one = self.take(4, "the endianness check")?;
            let a: [u8; 4] = one.try_into().expect("4 bytes");
            self.little_endian = match (i32::from_le_bytes(a), i32::from_be_bytes(a)) {
                (1, _) => true,
                (_, 1) => false,
                _ => return Err(err(self.file, at, "the endianness check is not the integer 1")),
            };
        }
        self.end_section("MeshFormat")
    }

    fn physical_names(&mut self, raw: &mut Raw) -> Result<(), MeshError> {
        let n = self.uint("the number of physical names")?;
        for _ in 0..n {
            let dim = self.uint("a physical dimension")?;
            let tag = self.int("a physical tag")?;
            // The name is the rest of the line, in quotes.
            let line_no = self.line;
            let rest = self.next_line().unwrap_or("").trim();
            let name = rest.strip_prefix('"').and_then(|r| r.strip_suffix('"')).ok_or_else(|| {
                err(self.file, At::Line(line_no), format!("expected a quoted name, found `{}`", truncate(rest)))
            })?;
            raw.names.insert((dim.min(3) as u32, tag), name.to_string());
        }
        Ok(())
    }

    fn entities(&mut self) -> Result<HashMap<(u32, i64), Vec<i64>>, MeshError> {
        let counts = [
            self.uint("the number of points")?,
            self.uint("the number of curves")?,
            self.uint("the number of surfaces")?,
            self.uint("the number of volumes")?,
        ];
        let mut map = HashMap::new();
        for (dim, &count) in counts.iter().enumerate() {
            for _ in 0..count {
                let tag = self.int("an entity tag")?;
                let coords = if dim == 0 { 3 } else { 6 };
                for _ in 0..coords {
                    self.float("an entity coordinate")?;
                }
                let nphys = self.uint("the number of physical tags")?;
                let mut phys = Vec::new();
                for _ in 0..nphys {
                    phys.push(self.int("a physical tag")?);
                }
                if dim > 0 {
                    let nb = self.uint("the number of bounding entities")?;
                    for _ in 0..nb {
                        self.int("a bounding entity tag")?;
                    }
                }
                map.insert((dim as u32, tag), phys);
            }
        }
        Ok(map)
    }

    fn nodes2(&mut self, raw: &mut Raw) -> Result<(), MeshError> {
        let n = self.uint("the number of nodes")?;
        for _ in 0..n {
            let tag = self.uint("a node tag")?;
            let at = self.here();
            let x = [self.float("x")?, self.float("y")?, self.float("z")?];
            raw.nodes.push((tag, x, at));
        }
        Ok(())
    }

    fn nodes4(&mut self, raw: &mut Raw) -> Result<(), MeshError> {
        let at = self.here();
        let blocks = self.uint("the number of node blocks")?;
        let total = self.uint("the number of nodes")?;
        self.uint("the smallest node tag")?;
        self.uint("the largest node tag")?;
        let before = raw.nodes.len();
        for _ in 0..blocks {
            self.small("an entity dimension")?;
            self.small("an entity tag")?;
            let parametric = self.small("the parametric flag")?;
            let count = self.uint("the number of nodes in the block")?;
            if parametric != 0 {
                return Err(self.error("parametric node coordinates are not supported (save without them)"));
            }
            let mut tags = Vec::new();
            for _ in 0..count {
                tags.push((self.uint("a node tag")?, self.at()));
            }
            for (tag, _) in tags {
                let at = self.here();
                let x = [self.float("x")?, self.float("y")?, self.float("z")?];
                raw.nodes.push((tag, x, at));
            }
        }
        if (raw.nodes.len() - before) as u64 != total {
            return Err(err(
                self.file,
                at,
                format!("the header announces {total} nodes, the blocks hold {}", raw.nodes.len() - before),
            ));
        }
        Ok(())
    }

    fn elements2(&mut self, raw: &mut Raw) -> Result<(), MeshError> {
        let n = self.uint("the number of elements")?;
        for _ in 0..n {
            let at = self.here();
            let tag = self.uint("an element tag")?;
            let kind = self.uint("an element type")? as u32;
            let ntags = self.uint("the number of element tags")?;
            let mut tags = Vec::new();
            for _ in 0..ntags {
                tags.push(self.int("an element tag")?);
            }
            let count = node_count(kind).ok_or_else(|| err(self.file, at, format!("unknown element type {kind}")))?;
            let mut nodes = Vec::new();
            for _ in 0..count {
                nodes.push(self.uint("a node tag")?);
            }
            // The first tag is the physical group (0: none).
            let physicals = tags.first().filter(|&&p| p != 0).map(|&p| vec![p]).unwrap_or_default();
            if element_info(kind).is_some() {
                raw.elements.push(RawElement { tag, kind, nodes, physicals, at });
            } else {
                raw.skipped.push((kind, tag, at));
            }
        }
        Ok(())
    }

    fn elements4(&mut self, raw: &mut Raw, entity_physicals: &HashMap<(u32, i64), Vec<i64>>) -> Result<(), MeshError> {
        let at_header = self.here();
        let blocks = self.uint("the number of element blocks")?;
        let total = self.uint("the number of elements")?;
        self.uint("the smallest element tag")?;
        self.uint("the largest element tag")?;
        let mut read = 0u64;
        for _ in 0..blocks {
            let dim = self.small("an entity dimension")?;
            let entity = self.small("an entity tag")? as i64;
            let at = self.here();
            let kind = self.small("an element type")? as u32;
            let count = self.uint("the number of elements in the block")?;
            let nodes_per = match (element_info(kind), other_element_info(kind)) {
                (Some((d, c)), _) | (None, Some((d, c, _))) => {
                    if u64::from(d) != dim {
                        return Err(err(
                            self.file,
                            at,
                            format!("element type {kind} has dimension {d}, but its block says {dim}"),
                        ));
                    }
                    c
                }
                (None, None) => return Err(err(self.file, at, format!("unknown element type {kind}"))),
            };
            let physicals = entity_physicals.get(&(dim as u32, entity)).cloned().unwrap_or_default();
            for _ in 0..count {
                let at = self.here();
                let tag = self.uint("an element tag")?;
                let mut nodes = Vec::new();
                for _ in 0..nodes_per {
                    nodes.push(self.uint("a node tag")?);
                }
                if element_info(kind).is_some() {
                    raw.elements.push(RawElement { tag, kind, nodes, physicals: physicals.clone(), at });
                } else {
                    raw.skipped.push((kind, tag, at));
                }
                read += 1;
            }
        }
        if read != total {
            return Err(err(
                self.file,
                at_header,
                format!("the header announces {total} elements, the blocks hold {read}"),
            ));
        }
        Ok(())
    }
}

fn truncate(s: &str) -> String {
    if s.chars().count() > 40 { format!("{}…", s.chars().take(40).collect::<String>()) } else { s.to_string() }
}

fn build(mut raw: Raw, file: &str) -> Result<Mesh, MeshError> {
    // Node numbering by increasing tag; tags must be distinct.
    raw.nodes.sort_by_key(|(tag, _, _)| *tag);
    for w in raw.nodes.windows(2) {
        if w[0].0 == w[1].0 {
            return Err(err(file, w[1].2, format!("node tag {} is repeated", w[1].0)));
        }
    }
    let index_of = |tag: u64| raw.nodes.binary_search_by_key(&tag, |(t, _, _)| *t).ok();
    let dim = raw.elements.iter().filter_map(|e| element_info(e.kind)).map(|(d, _)| d).max().unwrap_or(0);
    let warnings = skipped_elements(&raw, dim, file)?;
    if dim == 0 {
        return Err(MeshError::File {
            file: file.to_string(),
            reason: "no lines, triangles or tetrahedra in `$Elements`".into(),
        });
    }
    let mut cells: Vec<&RawElement> =
        raw.elements.iter().filter(|e| element_info(e.kind).is_some_and(|(d, _)| d == dim)).collect();
    cells.sort_by_key(|e| e.tag);
    let kind = match ElementKind::from_gmsh(cells[0].kind) {
        Some(kind) => kind,
        None => {
            let k = cells[0].kind;
            let supported: Vec<String> =
                crate::fem::element::ELEMENTS.iter().map(|e| format!("{} ({})", e.name, e.gmsh)).collect();
            return Err(err(
                file,
                cells[0].at,
                format!("element type {k} cannot be a cell (supported: {})", supported.join(", ")),
            ));
        }
    };
    if let Some(other) = cells.iter().find(|e| e.kind != cells[0].kind) {
        return Err(err(
            file,
            other.at,
            format!("mixed cell types ({} and {}): one element kind per mesh", cells[0].kind, other.kind),
        ));
    }
    for w in cells.windows(2) {
        if w[0].tag == w[1].tag {
            return Err(err(file, w[1].at, format!("element tag {} is repeated", w[1].tag)));
        }
    }
    // Keep only the nodes cells use, in tag order.
    let mut used = vec![false; raw.nodes.len()];
    let mut cell_nodes: Vec<usize> = Vec::new();
    for e in &cells {
        for &t in &e.nodes {
            let i = index_of(t).ok_or_else(|| {
                err(file, e.at, format!("element {} refers to node {t}, which is not in `$Nodes`", e.tag))
            })?;
            used[i] = true;
            cell_nodes.push(i);
        }
    }
    let mut new_index = vec![u32::MAX; raw.nodes.len()];
    let mut coords = Vec::new();
    for (i, (_, x, at)) in raw.nodes.iter().enumerate() {
        if used[i] {
            new_index[i] = (coords.len() / dim as usize) as u32;
            if x[dim as usize..].iter().any(|v| *v != 0.0) {
                return Err(err(
                    file,
                    *at,
                    format!("a {dim}D mesh must lie in the plane of its first {dim} coordinates (this node has {x:?})"),
                ));
            }
            coords.extend_from_slice(&x[..dim as usize]);
        }
    }
    let cells_flat: Vec<u32> = cell_nodes.iter().map(|&i| new_index[i]).collect();
    let mut mesh = Mesh {
        kind,
        coords,
        cells: cells_flat,
        regions: Vec::new(),
        cell_groups: Vec::new(),
        warnings,
        cell_size: super::CellSize::Diameter,
        sizes: Vec::new(),
    };
    mesh.validate().map_err(|e| located(e, &cells, file))?;
    let name_of = |d: u32, tag: i64| raw.names.get(&(d, tag)).cloned().unwrap_or_else(|| format!("physical_{tag}"));
    // Cell groups.
    let mut groups: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    for (c, e) in cells.iter().enumerate() {
        for &p in &e.physicals {
            groups.entry(name_of(dim, p)).or_default().push(c as u32);
        }
    }
    mesh.cell_groups = groups.into_iter().collect();
    // Elements one dimension below the cells must be facets of cells: anything else is a cell
    // of another dimension mixed in (triangles beside a tetrahedron), which would be dropped.
    // Those in physical groups become boundary regions, matched by vertices.
    let facet_elements: Vec<&RawElement> =
        raw.elements.iter().filter(|e| element_info(e.kind).is_some_and(|(d, _)| d + 1 == dim)).collect();
    if !facet_elements.is_empty() {
        // Some(facet) on the boundary, None inside.
        let mut facet_of: HashMap<[u32; 3], Option<Facet>> = HashMap::new();
        for c in 0..mesh.num_cells() {
            let cell = mesh.cell(c);
            for (f, verts) in kind.info().facets.iter().enumerate() {
                let vs: Vec<u32> = verts.iter().map(|&v| cell[v]).collect();
                facet_of
                    .entry(facet_key(&vs))
                    .and_modify(|e| *e = None)
                    .or_insert(Some(Facet { cell: c as u32, local: f as u8 }));
            }
        }
        let mixed = |e: &RawElement| {
            err(
                file,
                e.at,
                format!(
                    "element {} (type {}, dimension {}) is neither a cell nor a facet of one: \
                     the mesh mixes cells of dimensions {} and {dim}",
                    e.tag,
                    e.kind,
                    dim - 1,
                    dim - 1
                ),
            )
        };
        let mut regions: BTreeMap<String, Vec<Facet>> = BTreeMap::new();
        let vertices = dim as usize; // a facet of a d-simplex has d vertices
        for e in facet_elements {
            let mut vs = Vec::with_capacity(vertices);
            for &t in e.nodes.iter().take(vertices) {
                let i = index_of(t).ok_or_else(|| {
                    err(file, e.at, format!("element {} refers to node {t}, which is not in `$Nodes`", e.tag))
                })?;
                if new_index[i] == u32::MAX {
                    if e.physicals.is_empty() {
                        return Err(mixed(e));
                    }
                    return Err(err(
                        file,
                        e.at,
                        format!("boundary element {} uses node {t}, which no cell uses", e.tag),
                    ));
                }
                vs.push(new_index[i]);
            }
            let found = facet_of.get(&facet_key(&vs));
            if e.physicals.is_empty() {
                if found.is_none() {
                    return Err(mixed(e));
                }
                continue;
            }
            let f = found
                .copied()
                .flatten()
                .ok_or_else(|| err(file, e.at, format!("element {} is not a boundary facet of any cell", e.tag)))?;
            for &p in &e.physicals {
                regions.entry(name_of(dim - 1, p)).or_default().push(f);
            }
        }
        for (name, mut facets) in regions {
            facets.sort_unstable();
            facets.dedup();
            mesh.regions.push(Region { name, facets });
        }
    }
    // A named boundary group without elements stays a region, empty: a case that asks for it
    // then says so, instead of falling back to a default choice of facets.
    let mut declared: Vec<&String> =
        raw.names.iter().filter(|((d, _), _)| *d + 1 == dim).map(|(_, name)| name).collect();
    declared.sort();
    for name in declared {
        if !mesh.has_region(name) {
            mesh.regions.push(Region { name: name.clone(), facets: Vec::new() });
        }
    }
    Ok(mesh)
}

/// A validation error at the line (byte) of the element it names, with element tags (Gmsh
/// numbers) beside our cell numbers.
fn located(e: MeshError, cells: &[&RawElement], file: &str) -> MeshError {
    let tags = |cs: &[usize]| -> Vec<String> { cs.iter().map(|&c| cells[c].tag.to_string()).collect() };
    match e {
        MeshError::Degenerate { cell, .. } | MeshError::Inverted { cell } => {
            err(file, cells[cell].at, format!("element {}: {e}", cells[cell].tag))
        }
        MeshError::DuplicateCell { first, second } | MeshError::SameSide { first, second } => {
            let t = tags(&[first, second]);
            err(file, cells[second].at, format!("elements {} and {}: {e}", t[0], t[1]))
        }
        MeshError::FacetSharedByMany { cells: ref cs } if !cs.is_empty() => {
            let at = cells[cs[cs.len() - 1]].at;
            err(file, at, format!("elements {}: {e}", tags(cs).join(", ")))
        }
        other => MeshError::File { file: file.to_string(), reason: other.to_string() },
    }
}

/// Elements of types we do not use. Those of the cells' dimension or above are part of the
/// body: dropping them would leave a hole, so they are an error. Lower ones (quadrangle faces
/// beside tetrahedra) only lose their physical groups: a warning, by type and count.
fn skipped_elements(raw: &Raw, dim: u32, file: &str) -> Result<Vec<String>, MeshError> {
    let mut by_kind: BTreeMap<u32, (usize, u64, At)> = BTreeMap::new();
    for &(kind, tag, at) in &raw.skipped {
        by_kind.entry(kind).or_insert((0, tag, at)).0 += 1;
    }
    let mut warnings = Vec::new();
    for (kind, (count, tag, at)) in by_kind {
        let Some((d, _, name)) = other_element_info(kind) else { continue };
        if d >= dim {
            return Err(err(
                file,
                at,
                format!(
                    "element {tag} is a {name} (type {kind}, {count} in the file): cells must be \
                     lines, triangles or tetrahedra (one kind per mesh), and dropping it would leave a hole"
                ),
            ));
        }
        let w = format!(
            "{file}: skipped {count} {name} element(s) (type {kind}), which a {dim}D simplex mesh does not use"
        );
        tracing::warn!("{w}");
        warnings.push(w);
    }
    Ok(warnings)
}
