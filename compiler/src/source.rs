//! Source files of one compilation: their names, texts and the loader that reads imports.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use codespan_reporting::files::SimpleFiles;

/// Index of a file in a [`SourceMap`].
pub type FileId = usize;

/// A byte range in one source file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Span {
    pub file: FileId,
    pub start: usize,
    pub end: usize,
}

impl Span {
    pub fn new(file: FileId, start: usize, end: usize) -> Self {
        Span { file, start, end }
    }

    /// The smallest span covering both (same file assumed).
    pub fn to(self, other: Span) -> Span {
        Span { file: self.file, start: self.start.min(other.start), end: self.end.max(other.end) }
    }
}

/// The texts of every file read during one compilation, for diagnostics.
#[derive(Default)]
pub struct SourceMap {
    pub(crate) files: SimpleFiles<String, String>,
    paths: Vec<PathBuf>,
}

impl SourceMap {
    pub fn add(&mut self, path: PathBuf, text: String) -> FileId {
        self.paths.push(path.clone());
        self.files.add(path.display().to_string(), text)
    }

    pub fn text(&self, file: FileId) -> &str {
        self.files.get(file).map(|f| f.source().as_str()).unwrap_or("")
    }

    pub fn path(&self, file: FileId) -> &Path {
        &self.paths[file]
    }

    pub fn slice(&self, span: Span) -> &str {
        self.text(span.file).get(span.start..span.end).unwrap_or("")
    }

    pub fn len(&self) -> usize {
        self.paths.len()
    }

    pub fn is_empty(&self) -> bool {
        self.paths.is_empty()
    }

    /// 1-based (line, column) of a byte offset.
    pub fn line_col(&self, file: FileId, offset: usize) -> (usize, usize) {
        let text = self.text(file);
        let offset = offset.min(text.len());
        let before = &text[..offset];
        let line = before.matches('\n').count() + 1;
        let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (line, col)
    }
}

/// Reads source files (the filesystem, or an in-memory map for tests and fuzzing).
pub trait Loader {
    fn load(&self, path: &Path) -> std::io::Result<String>;

    /// The file a run binds to a role (`import material = elasticity` reads the run's material
    /// in place of `elasticity.wf`); `None` keeps the file the import names.
    fn role(&self, _role: &str) -> Option<PathBuf> {
        None
    }
}

/// Reads from the filesystem.
pub struct FsLoader;

impl Loader for FsLoader {
    fn load(&self, path: &Path) -> std::io::Result<String> {
        read_source(path)
    }
}

/// The most bytes of a `.wf` file: a larger one is not a source file (`/dev/zero`, a mesh given
/// by mistake), and is refused after reading that much.
pub const MAX_SOURCE_BYTES: u64 = 1 << 20;

/// A `.wf` file's text, read up to [`MAX_SOURCE_BYTES`].
pub fn read_source(path: &Path) -> std::io::Result<String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?.take(MAX_SOURCE_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_SOURCE_BYTES {
        return Err(std::io::Error::other(format!(
            "larger than {} KiB, the limit of a .wf file (not a .wf file?)",
            MAX_SOURCE_BYTES >> 10
        )));
    }
    decode(bytes)
}

/// UTF-8 text without the byte-order mark some editors write; invalid UTF-8 is an error whose
/// message starts with `line:column:` of the first bad byte.
fn decode(bytes: Vec<u8>) -> std::io::Result<String> {
    match String::from_utf8(bytes) {
        Ok(text) => Ok(match text.strip_prefix('\u{feff}') {
            Some(rest) => rest.to_string(),
            None => text,
        }),
        Err(e) => {
            let good = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let line = good.iter().filter(|&&b| b == b'\n').count() + 1;
            let start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            let col = String::from_utf8_lossy(&good[start..]).chars().count() + 1;
            Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("{line}:{col}: not UTF-8 text (byte 0x{:02x})", e.as_bytes()[good.len()]),
            ))
        }
    }
}

/// Serves files from memory, keyed by path.
#[derive(Default, Clone)]
pub struct MemLoader {
    pub files: HashMap<PathBuf, String>,
}

impl MemLoader {
    pub fn with(mut self, path: impl Into<PathBuf>, text: impl Into<String>) -> Self {
        self.files.insert(path.into(), text.into());
        self
    }
}

impl Loader for MemLoader {
    fn load(&self, path: &Path) -> std::io::Result<String> {
        self.files
            .get(&normalize(path))
            .cloned()
            .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"))
    }
}

/// The default module name of a .wf file: its stem. (Here, below every stage, because codegen
/// and the docs name files too, and the pipeline runs them.)
pub fn module_name(path: &Path) -> String {
    path.file_stem().map_or_else(|| "forms".to_string(), |s| s.to_string_lossy().into_owned())
}

/// The file name shown in generated documentation (no machine-specific directories).
pub fn display_name(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |s| s.to_string_lossy().into_owned())
}

/// Lexical normalisation (`a/./b/../c` → `a/c`), so that one file imported along two paths is
/// recognised as one without touching the filesystem.
pub fn normalize(path: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}
