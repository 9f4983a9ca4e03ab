//! Form files a run uses: compiled into the library, or given by path and interpreted (the IR
//! evaluated on the runtime's tabulations, `crate::interpret`). Both describe themselves with
//! the same param, coef and slot data and instantiate the same bound forms.

use std::path::{Path, PathBuf};

use crate::compiler::{Failure, check_path, describe, module_name};
use crate::interpret::Library;
use crate::runtime::descriptors::{ParamInfo, SlotInfo};
use crate::runtime::fem::kernel::Coef;
use crate::runtime::library::{Binding, LibraryError, Made, Unit};

/// A form file in use.
pub enum FormSource {
    Compiled(&'static Unit),
    Interpreted(Box<Interpreted>),
}

/// A form file compiled at run time.
pub struct Interpreted {
    pub name: String,
    pub file: String,
    pub params: Vec<ParamInfo>,
    pub slots: Vec<SlotInfo>,
    /// Written by the run itself (a problem's loads), not a file of the user's.
    pub generated: bool,
    /// A file of the library that the library itself interprets (a pair law: the code
    /// generator does not compile them yet), not a file of the user's.
    pub library: bool,
    /// The roles its files import: role and default file stem.
    pub roles: Vec<(String, String)>,
    /// A file of the library compiled again for the run's material (the file bound to its
    /// `import material = ...`), which is named here.
    pub rebound: Option<String>,
    lib: Library,
}

/// Checks and lowers a form file given by path, with `roles` bound to files (role, path).
pub fn interpret(path: &Path, roles: &[(String, PathBuf)]) -> Result<Interpreted, Failure> {
    let (prog, warnings) = check_path(path, &BoundLoader { roles })?;
    if !warnings.is_empty() {
        eprint!("{warnings}");
    }
    Ok(Interpreted {
        name: module_name(path),
        file: path.display().to_string(),
        params: describe::params(&prog),
        slots: describe::slots(&prog),
        generated: false,
        library: false,
        roles: roles_of(&prog),
        rebound: None,
        lib: Library::new(&prog),
    })
}

impl Interpreted {
    /// Its lowered forms.
    pub fn library(&self) -> &Library {
        &self.lib
    }
}

fn roles_of(prog: &crate::compiler::Program) -> Vec<(String, String)> {
    prog.roles.iter().map(|r| (r.name.clone(), r.read.clone())).collect()
}

/// Checks and lowers a form file the run writes itself (`name` is how messages name it).
pub fn interpret_text(name: &str, text: &str) -> Result<Interpreted, Failure> {
    interpret_source(name, text, true)
}

/// A contact pair law of the library (`forms/pairs/`) by its file stem (`pair_penalty`),
/// checked and lowered from the text built in.
pub fn library_pair(name: &str) -> Option<Result<Interpreted, Failure>> {
    let (stem, text) = crate::forms::PAIR_SOURCES.iter().find(|(stem, _)| *stem == name)?;
    Some(interpret_source(&format!("forms/pairs/{stem}.wf"), text, false).map(|i| Interpreted { library: true, ..i }))
}

/// The library's pair laws, by file stem.
pub fn pair_names() -> Vec<&'static str> {
    crate::forms::PAIR_SOURCES.iter().map(|(stem, _)| *stem).collect()
}

fn interpret_source(name: &str, text: &str, generated: bool) -> Result<Interpreted, Failure> {
    let path = Path::new(name);
    let prog = crate::compiler::pipeline::check_text(path, text, &LibraryLoader)
        .map_err(|(diags, sources)| Failure::of(&diags, &sources))?;
    Ok(Interpreted {
        name: module_name(path),
        file: name.to_string(),
        params: describe::params(&prog),
        slots: describe::slots(&prog),
        generated,
        library: false,
        roles: roles_of(&prog),
        rebound: None,
        lib: Library::new(&prog),
    })
}

impl Interpreted {
    fn make<'m>(
        &self,
        values: &[f64],
        coefs: &dyn Fn(&str) -> Option<Coef>,
        binding: &Binding<'m>,
    ) -> Result<Made<'_, 'm>, LibraryError> {
        let params: Vec<(&str, f64)> = self.params.iter().map(|p| &*p.name).zip(values.iter().copied()).collect();
        let mut data = Vec::new();
        for name in self.lib.coefs() {
            let c = coefs(name)
                .ok_or_else(|| LibraryError::MissingCoef { name: name.to_string(), declared: self.file.clone() })?;
            data.push((name, c));
        }
        let mut made = Vec::new();
        for slot in &self.slots {
            let form = self
                .lib
                .form(&slot.name, binding.dim, &params, &data)
                .map_err(|e| LibraryError::Coef(e.to_string()))?;
            let bound = match (self.lib.is_pair_law(), slot.functional) {
                (true, functional) => binding.pair(form, functional)?,
                (false, true) => binding.functional(form)?,
                (false, false) => binding.form(form)?,
            };
            made.push((&*slot.name, bound));
        }
        Ok(made)
    }
}

impl FormSource {
    pub fn name(&self) -> &str {
        match self {
            FormSource::Compiled(u) => u.name,
            FormSource::Interpreted(i) => &i.name,
        }
    }

    pub fn file(&self) -> &str {
        match self {
            FormSource::Compiled(u) => u.file,
            FormSource::Interpreted(i) => &i.file,
        }
    }

    pub fn params(&self) -> &[ParamInfo] {
        match self {
            FormSource::Compiled(u) => u.forms.map_or(&[][..], |f| f.params),
            FormSource::Interpreted(i) => &i.params,
        }
    }

    pub fn slots(&self) -> &[SlotInfo] {
        match self {
            FormSource::Compiled(u) => u.forms.map_or(&[][..], |f| f.slots),
            FormSource::Interpreted(i) => &i.slots,
        }
    }

    pub fn interpreted(&self) -> bool {
        matches!(self, FormSource::Interpreted(_))
    }

    /// The roles its files import (`import material = elasticity`): role and default file stem.
    pub fn roles(&self) -> Vec<(String, String)> {
        match self {
            FormSource::Compiled(u) => {
                u.forms.map_or(Vec::new(), |f| f.roles.iter().map(|(r, d)| (r.to_string(), d.to_string())).collect())
            }
            FormSource::Interpreted(i) => i.roles.clone(),
        }
    }

    /// The coefs the file's forms read (its own and its imports'): name and tensor rank.
    pub fn coefs(&self) -> Vec<(String, u32)> {
        match self {
            FormSource::Compiled(u) => {
                u.forms.map_or(Vec::new(), |f| f.coefs.iter().map(|c| (c.name.to_string(), c.rank)).collect())
            }
            FormSource::Interpreted(i) => i.lib.coef_ranks(),
        }
    }

    /// Instantiates every form of the file: param values in `params()` order.
    pub fn make<'m>(
        &self,
        values: &[f64],
        coefs: &dyn Fn(&str) -> Option<Coef>,
        binding: &Binding<'m>,
    ) -> Result<Made<'_, 'm>, LibraryError> {
        match self {
            FormSource::Compiled(u) => match u.forms {
                Some(f) => (f.make)(values, coefs, binding),
                None => Ok(Vec::new()),
            },
            FormSource::Interpreted(i) => i.make(values, coefs, binding),
        }
    }
}

/// [`LibraryLoader`] with files bound to roles (`import material = elasticity` reads the run's
/// material).
struct BoundLoader<'a> {
    roles: &'a [(String, PathBuf)],
}

impl crate::compiler::Loader for BoundLoader<'_> {
    fn load(&self, path: &Path) -> std::io::Result<String> {
        LibraryLoader.load(path)
    }

    fn role(&self, role: &str) -> Option<PathBuf> {
        self.roles.iter().find(|(r, _)| r == role).map(|(_, p)| p.clone())
    }
}

/// Reads files from disk; an import of a library file (`import elasticity`) that is not beside
/// the importing file is served from the library's own text.
pub struct LibraryLoader;

impl crate::compiler::Loader for LibraryLoader {
    fn load(&self, path: &Path) -> std::io::Result<String> {
        match crate::compiler::Loader::load(&crate::compiler::FsLoader, path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
                let mut library = crate::forms::SOURCES.iter().chain(crate::forms::PAIR_SHARED_SOURCES);
                library.find(|(n, _)| *n == name).map(|(_, text)| text.to_string()).ok_or(e)
            }
            other => other,
        }
    }
}
