//! Loading a compilation unit: the root file and, transitively, its imports (each file once,
//! imports before importers), with missing and cyclic imports reported at the `import` line.

use std::path::{Path, PathBuf};

use crate::diagnostic::Diagnostic;
use crate::source::{FileId, Loader, SourceMap, Span, normalize};
use crate::syntax::{ast, parse};

/// Files of one unit, imports first, the root last.
pub struct Loaded {
    pub sources: SourceMap,
    pub files: Vec<(FileId, ast::File)>,
    pub root: FileId,
    /// The roles imported, with the file read for each.
    pub roles: Vec<super::Role>,
}

/// Reads and parses `root` and everything it imports. Syntax errors do not stop loading.
pub fn load(root: &Path, loader: &dyn Loader, diags: &mut Vec<Diagnostic>) -> Result<Loaded, String> {
    let root = normalize(root);
    let text = loader.load(&root).map_err(|e| match e.kind() {
        std::io::ErrorKind::InvalidData => format!("{}:{e}", root.display()),
        _ => format!("cannot read {}: {e}", root.display()),
    })?;
    let mut l =
        Loader_ { loader, sources: SourceMap::default(), files: Vec::new(), stack: Vec::new(), roles: Vec::new() };
    let root_id = l.sources.add(root.clone(), text);
    l.visit(root_id, diags);
    Ok(Loaded { sources: l.sources, files: l.files, root: root_id, roles: l.roles })
}

/// Parses a single in-memory text as a unit whose imports resolve through `loader`.
pub fn load_text(path: &Path, text: &str, loader: &dyn Loader, diags: &mut Vec<Diagnostic>) -> Loaded {
    let mut l =
        Loader_ { loader, sources: SourceMap::default(), files: Vec::new(), stack: Vec::new(), roles: Vec::new() };
    let root_id = l.sources.add(normalize(path), text.to_string());
    l.visit(root_id, diags);
    Loaded { sources: l.sources, files: l.files, root: root_id, roles: l.roles }
}

struct Loader_<'a> {
    loader: &'a dyn Loader,
    sources: SourceMap,
    files: Vec<(FileId, ast::File)>,
    /// Files being visited, with the span of the import that led to each.
    stack: Vec<(PathBuf, Option<Span>)>,
    roles: Vec<super::Role>,
}

impl Loader_<'_> {
    fn visit(&mut self, id: FileId, diags: &mut Vec<Diagnostic>) {
        let path = self.sources.path(id).to_path_buf();
        self.stack.push((path.clone(), None));
        let (file, mut d) = parse(id, self.sources.text(id));
        diags.append(&mut d);
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        for item in &file.items {
            let ast::Item::Import { path: rel, span, role } = item else {
                continue;
            };
            let bound = role.as_ref().and_then(|r| self.loader.role(&r.name));
            let target = normalize(&bound.unwrap_or_else(|| dir.join(rel)));
            if let Some(r) = role
                && !self.roles.iter().any(|o| o.name == r.name)
            {
                let stem = |p: &Path| p.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
                self.roles.push(super::Role {
                    name: r.name.clone(),
                    default: stem(Path::new(rel)),
                    read: stem(&target),
                });
            }
            if let Some(pos) = self.stack.iter().position(|(p, _)| *p == target) {
                let mut d =
                    Diagnostic::error("E0702", "cyclic import", *span, format!("`{}` is already being imported", rel))
                        .with_note(cycle_note(&self.stack[pos..], &target));
                if let Some(first) = self.stack[pos + 1..].iter().find_map(|(_, s)| *s) {
                    d = d.with_label(first, "the cycle starts here");
                }
                diags.push(d);
                continue;
            }
            if (0..self.sources.len()).any(|f| self.sources.path(f) == target) {
                continue; // already loaded through another path
            }
            match self.loader.load(&target) {
                Ok(text) => {
                    self.stack.last_mut().expect("current file on stack").1 = Some(*span);
                    let child = self.sources.add(target, text);
                    self.visit(child, diags);
                }
                Err(e) => diags.push(
                    Diagnostic::error("E0701", "missing import", *span, format!("cannot read `{}`: {e}", target.display()))
                        .with_help("imports are resolved relative to the importing file; `import elasticity` reads `elasticity.wf`"),
                ),
            }
        }
        self.stack.pop();
        self.files.push((id, file));
    }
}

fn cycle_note(stack: &[(PathBuf, Option<Span>)], back: &Path) -> String {
    let mut names: Vec<String> = stack.iter().map(|(p, _)| file_name(p)).collect();
    names.push(file_name(back));
    format!("import cycle: {}", names.join(" → "))
}

fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(|| p.display().to_string(), |f| f.to_string_lossy().into_owned())
}
