//! The report's tables and failures: a Markdown table whose rows have their header's cells
//! (checked by the type), each cell on one line; a failed run's full message kept in a file
//! beside the report, and a short cause in its cell.

use std::path::{Path, PathBuf};

/// A Markdown table: a header and rows of as many cells.
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new<S: AsRef<str>>(header: &[S]) -> Table {
        Table { header: header.iter().map(|h| h.as_ref().to_string()).collect(), rows: Vec::new() }
    }

    /// A row of the header's number of cells (the report's own code: a mismatch is its bug).
    pub fn row<const N: usize>(&mut self, cells: [String; N]) {
        assert_eq!(N, self.header.len(), "a row of {N} cells under {:?}", self.header);
        self.rows.push(cells.to_vec());
    }

    /// A row of any length, for tables whose columns are not fixed (checked as `row`).
    pub fn row_vec(&mut self, cells: Vec<String>) {
        assert_eq!(cells.len(), self.header.len(), "a row of {} cells under {:?}", cells.len(), self.header);
        self.rows.push(cells);
    }

    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The table, or a sentence saying it has no rows (a Markdown table needs at least one).
    pub fn markdown(&self) -> String {
        if self.rows.is_empty() {
            return "No run of this table finished.\n".to_string();
        }
        let line =
            |cells: &[String]| format!("| {} |\n", cells.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | "));
        let mut md = line(&self.header);
        md.push_str(&format!("|{}\n", "---|".repeat(self.header.len())));
        for r in &self.rows {
            md.push_str(&line(r));
        }
        md
    }
}

/// A cell's text on one line, with its pipes escaped.
fn cell(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ").replace('|', "\\|")
}

/// Where the report keeps the full messages of the runs that failed (`failures/NAME.txt`
/// beside report.md).
pub struct Failures {
    dir: PathBuf,
}

impl Failures {
    pub fn new(out: &Path) -> Failures {
        Failures { dir: out.to_path_buf() }
    }

    /// The cell of a failed run `name`: its cause in a sentence, linked to its full message.
    pub fn cell(&self, name: &str, message: &str) -> String {
        let file: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' { c } else { '_' }).collect();
        let path = self.dir.join("failures").join(format!("{file}.txt"));
        let written = std::fs::create_dir_all(self.dir.join("failures"))
            .and_then(|()| crate::output::write_atomic(&path, message.as_bytes()));
        match written {
            Ok(()) => format!("failed: {} ([message](failures/{file}.txt))", cause(message)),
            Err(_) => format!("failed: {}", cause(message)),
        }
    }
}

/// A message's cause in a sentence: its first line, cut at a word near 90 characters.
pub fn cause(message: &str) -> String {
    const MAX: usize = 90;
    let first = message.lines().next().unwrap_or("").trim();
    let first = first.strip_prefix("error: ").unwrap_or(first);
    if first.chars().count() <= MAX {
        return first.to_string();
    }
    let cut: String = first.chars().take(MAX).collect();
    let at = cut.rfind(' ').unwrap_or(cut.len());
    format!("{}…", cut[..at].trim_end_matches([',', ';', ':']))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_stay_on_one_line_with_their_pipes_escaped() {
        let mut t = Table::new(&["a", "b"]);
        t.row(["x | y".into(), "one\ntwo".into()]);
        assert_eq!(t.markdown(), "| a | b |\n|---|---|\n| x \\| y | one two |\n");
        assert_eq!(Table::new(&["a"]).markdown(), "No run of this table finished.\n");
    }

    #[test]
    fn a_long_message_is_cut_at_a_word() {
        let long = format!("Newton did not converge {}\nsecond line", "after many iterations ".repeat(8));
        let c = cause(&long);
        assert!(c.ends_with('…') && c.chars().count() <= 91 && !c.contains('\n'), "{c}");
        assert_eq!(cause("error: short\nmore"), "short");
    }
}
