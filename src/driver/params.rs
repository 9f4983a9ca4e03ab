//! One options model for every param of a run: the scheme's and the form files'. Each param has
//! one default, the one in its .wf file; a case may override it (in its one list of
//! overrides), the user may set it (`--param NAME=VALUE`, `[params]` in a case file). A name is
//! `name`, or `owner.name` (`hht.alpha`, `elasticity.rho`) when two files declare it.

use std::collections::BTreeMap;

use serde::Serialize;

use super::{FormSource, SchemeSource};
use crate::error::CaseError;
use crate::runtime::descriptors::ParamInfo;

/// A user's `name = value`, with where it was written (for errors).
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    pub name: String,
    pub value: f64,
    /// `--param`, or `case.toml:12`.
    pub origin: String,
}

/// Where a param's value comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Source {
    /// The default in its .wf file.
    File,
    /// The case's override.
    Case,
    /// Set by the user.
    User,
}

/// A param in effect.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct ParamValue {
    pub value: f64,
    pub source: Source,
    /// `file.wf:line`.
    pub declared: String,
}

/// The params of `params` that file `stem`.wf declares (a contact law's, say), by their names
/// in the file, with their values.
pub fn declared_by(params: &BTreeMap<String, ParamValue>, stem: &str) -> Vec<(String, f64)> {
    let file = format!("{stem}.wf");
    params
        .iter()
        .filter(|(_, p)| {
            let declared = p.declared.rsplit_once(':').map_or(p.declared.as_str(), |(f, _)| f);
            std::path::Path::new(declared).file_name().is_some_and(|f| f.to_string_lossy() == file)
        })
        .map(|(name, p)| (name.rsplit('.').next().unwrap_or(name).to_string(), p.value))
        .collect()
}

struct Entry {
    info: ParamInfo,
    scheme: bool,
    value: f64,
    source: Source,
}

/// Every param of a run's scheme and form files.
pub struct Table {
    entries: Vec<Entry>,
}

fn same(a: &ParamInfo, b: &ParamInfo) -> bool {
    a.name == b.name && a.owner == b.owner && a.declared == b.declared
}

impl Table {
    pub fn new(scheme: Option<&SchemeSource>, units: &[FormSource]) -> Table {
        let mut entries: Vec<Entry> = scheme
            .map_or(&[][..], |s| s.params())
            .iter()
            .map(|p| Entry { info: p.clone(), scheme: true, value: p.default, source: Source::File })
            .collect();
        for p in units.iter().flat_map(|u| u.params().iter()) {
            if !entries.iter().any(|e| same(&e.info, p)) {
                entries.push(Entry { info: p.clone(), scheme: false, value: p.default, source: Source::File });
            }
        }
        Table { entries }
    }

    fn check(e: &Entry, value: f64, origin: &str) -> Result<(), CaseError> {
        if e.info.range.contains(value) {
            return Ok(());
        }
        Err(CaseError::Option(format!(
            "{origin}: param `{}` = {value} is outside its range {} (declared at {}: `{} = {}`)",
            e.info.name, e.info.range, e.info.declared, e.info.name, e.info.written
        )))
    }

    /// A case's overrides of the scheme's and form files' defaults (a problem's `set`); params
    /// the files in use do not declare are left alone (a user's contact law may have no
    /// `gamma0`, another scheme no `gam`).
    pub fn apply_case(&mut self, overrides: &[(&str, f64)]) -> Result<(), CaseError> {
        for &(name, value) in overrides {
            for e in self.entries.iter_mut().filter(|e| e.info.name == name) {
                Self::check(e, value, "the case's override")?;
                e.value = value;
                e.source = Source::Case;
            }
        }
        Ok(())
    }

    /// The user's settings, each matching exactly one param.
    pub fn apply_user(&mut self, settings: &[Setting]) -> Result<(), CaseError> {
        for s in settings {
            let (owner, name) = match s.name.rsplit_once('.') {
                Some((o, n)) => (Some(o), n),
                None => (None, s.name.as_str()),
            };
            let owner_matches =
                |e: &Entry| owner.is_none_or(|o| e.info.owner == o || e.info.owner == format!("contact_{o}"));
            let hits: Vec<usize> = (0..self.entries.len())
                .filter(|&i| self.entries[i].info.name == name && owner_matches(&self.entries[i]))
                .collect();
            match hits.as_slice() {
                [i] => {
                    let e = &mut self.entries[*i];
                    Self::check(e, s.value, &s.origin)?;
                    e.value = s.value;
                    e.source = Source::User;
                }
                [] => return Err(self.unknown(s)),
                many => {
                    let options: Vec<String> = many
                        .iter()
                        .map(|&i| {
                            let e = &self.entries[i];
                            format!("`{}.{}` ({}: {})", e.info.owner, e.info.name, e.info.declared, e.info.doc)
                        })
                        .collect();
                    return Err(CaseError::Option(format!(
                        "{}: param `{}` is ambiguous: write {}",
                        s.origin,
                        s.name,
                        options.join(" or ")
                    )));
                }
            }
        }
        Ok(())
    }

    fn unknown(&self, s: &Setting) -> CaseError {
        let names: Vec<String> = self.entries.iter().map(|e| self.display_name(e)).collect();
        let hint = crate::compiler::check::suggest_name(&s.name, names.iter().map(String::as_str))
            .map_or(String::new(), |n| format!("; did you mean `{n}`?"));
        CaseError::Option(format!(
            "{}: unknown param `{}`: the scheme and form files in use declare {}{hint}",
            s.origin,
            s.name,
            if names.is_empty() { "none".to_string() } else { names.join(", ") }
        ))
    }

    /// `name`, or `owner.name` when another param has the same name.
    fn display_name(&self, e: &Entry) -> String {
        if self.entries.iter().filter(|o| o.info.name == e.info.name).count() > 1 {
            format!("{}.{}", e.info.owner, e.info.name)
        } else {
            e.info.name.to_string()
        }
    }

    fn value_of(&self, p: &ParamInfo, scheme: bool) -> f64 {
        self.entries.iter().find(|e| e.scheme == scheme && same(&e.info, p)).map_or(p.default, |e| e.value)
    }

    /// Values of a scheme's params, in order.
    pub fn scheme_values(&self, params: &[ParamInfo]) -> Vec<f64> {
        params.iter().map(|p| self.value_of(p, true)).collect()
    }

    /// Values of a form file's params, in order.
    pub fn unit_values(&self, params: &[ParamInfo]) -> Vec<f64> {
        params.iter().map(|p| self.value_of(p, false)).collect()
    }

    /// The value of a form param by name (the first declaration of that name).
    pub fn get(&self, name: &str) -> Option<f64> {
        self.entries.iter().find(|e| !e.scheme && e.info.name == name).map(|e| e.value)
    }

    /// Every param in effect, by display name (for summaries).
    pub fn values(&self) -> BTreeMap<String, ParamValue> {
        self.entries
            .iter()
            .map(|e| {
                (
                    self.display_name(e),
                    ParamValue { value: e.value, source: e.source, declared: e.info.declared.to_string() },
                )
            })
            .collect()
    }
}
