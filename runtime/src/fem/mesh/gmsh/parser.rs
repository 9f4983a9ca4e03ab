//! The sections of MSH 2.2 ASCII and MSH 4.1 ASCII and binary files, read into raw nodes,
//! elements and physical names, with every count and position checked.

use std::collections::HashMap;

use super::{At, Raw, RawElement, element_info, err, node_count, other_element_info, truncate};
use crate::fem::mesh::MeshError;

pub(super) struct Parser<'a> {
    bytes: &'a [u8],
    file: &'a str,
    pos: usize,
    line: usize,
    binary: bool,
    little_endian: bool,
    version: u32,
}

impl<'a> Parser<'a> {
    pub(super) fn new(bytes: &'a [u8], file: &'a str) -> Self {
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

    pub(super) fn parse(mut self) -> Result<Raw, MeshError> {
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
