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

#[derive(Clone)]
struct Entry {
    info: ParamInfo,
    scheme: bool,
    /// The roles of the file that declares it (`scheme`, `material`, `contact`, `forms`).
    roles: Vec<&'static str>,
    value: f64,
    source: Source,
}

impl Entry {
    /// Whether `owner.name` names this param: `owner` is a role (`material.rho`) or the
    /// declaring file's stem (`elasticity.rho`; `nitsche.theta` for `contact_nitsche`).
    fn answers(&self, owner: Option<&str>, name: &str) -> bool {
        self.info.name == name
            && owner.is_none_or(|o| {
                self.roles.contains(&o) || self.info.owner == o || self.info.owner == format!("contact_{o}")
            })
    }

    /// `owner.name` and the role's `role.name` (of the roles in `unique`), with the
    /// declaration: one choice of an ambiguous name.
    fn choice(&self, unique: &[&str]) -> String {
        let roles = self.roles.iter().filter(|r| unique.contains(r));
        let roles: Vec<String> = roles.map(|r| format!("`{r}.{}`", self.info.name)).collect();
        format!(
            "`{}.{}` ({}{}: {})",
            self.info.owner,
            self.info.name,
            if roles.is_empty() { String::new() } else { format!("or {}, ", roles.join(" or ")) },
            self.info.declared,
            self.info.doc
        )
    }
}

/// Splits `owner.name` (or `name`).
fn qualified(name: &str) -> (Option<&str>, &str) {
    match name.rsplit_once('.') {
        Some((o, n)) => (Some(o), n),
        None => (None, name),
    }
}

/// A case's override that names no one param: the setting's index, its name and why.
pub struct Unmatched {
    pub index: usize,
    pub name: String,
    pub why: Unnamed,
}

/// Why an override names no one param.
pub enum Unnamed {
    /// Several params answer to it: the choices, qualified.
    Several(Vec<String>),
    /// Its qualifier is no role and no file (of the library or in use): the closest.
    UnknownQualifier(Option<String>),
    /// A body's value of a param of the scheme (named), which is the problem's.
    SchemeParam(String),
    /// A pair's value of a param its law (named) does not declare: the files that do.
    NotTheLaw { law: String, owners: Vec<String> },
}

impl Unmatched {
    /// The message (after the place it was written).
    pub fn message(&self) -> String {
        match &self.why {
            Unnamed::Several(choices) => format!(
                "param `{}` is declared by more than one file in use: write {}",
                self.name,
                choices.join(" or ")
            ),
            Unnamed::UnknownQualifier(closest) => format!(
                "`{}` names no param of the files in use: its qualifier is neither a role ({}) nor a file{}",
                self.name,
                ROLES.join(", "),
                closest.as_ref().map_or(String::new(), |c| format!("; did you mean `{c}`?"))
            ),
            Unnamed::SchemeParam(scheme) => format!(
                "`{}` is a param of scheme `{scheme}`, which steps every body at once: set it at the problem's level",
                self.name
            ),
            Unnamed::NotTheLaw { law, owners } => format!(
                "`{}` is declared by {}, not by the pair's law `{law}`: a pair's `set` reaches its law's params; set it on a body or at the problem's level",
                self.name,
                owners.iter().map(|o| format!("`{o}`")).collect::<Vec<_>>().join(" and ")
            ),
        }
    }
}

/// The roles a qualified param name may start with (`material.rho`).
pub const ROLES: &[&str] = &["scheme", "material", "contact", "forms"];

/// Why a case's override was refused: a value out of its range, or a name several params
/// answer to (which the caller locates at the override).
pub enum CaseOverrideError {
    Invalid(CaseError),
    Unmatched(Unmatched),
}

/// Every param of a run's scheme and form files.
#[derive(Clone)]
pub struct Table {
    entries: Vec<Entry>,
}

fn same(a: &ParamInfo, b: &ParamInfo) -> bool {
    a.name == b.name && a.owner == b.owner && a.declared == b.declared
}

impl Table {
    /// `units`: the material (first), the contact laws (at `contact`: an obstacle's, each pair's)
    /// and the extra form files.
    pub fn new(scheme: Option<&SchemeSource>, units: &[FormSource], contact: &[usize]) -> Table {
        let mut entries: Vec<Entry> = scheme
            .map_or(&[][..], |s| s.params())
            .iter()
            .map(|p| Entry {
                info: p.clone(),
                scheme: true,
                roles: vec!["scheme"],
                value: p.default,
                source: Source::File,
            })
            .collect();
        // A file's role reaches the params it declares; a param only imported (elasticity's,
        // through a contact law) takes the roles of the files that import it.
        let mut imported: Vec<(usize, &'static str)> = Vec::new();
        for (i, u) in units.iter().enumerate() {
            let roles: Vec<&'static str> =
                [(i == 0, "material"), (contact.contains(&i), "contact"), (i != 0 && !contact.contains(&i), "forms")]
                    .into_iter()
                    .filter_map(|(holds, role)| holds.then_some(role))
                    .collect();
            for p in u.params() {
                let index = match entries.iter().position(|e| same(&e.info, p)) {
                    Some(k) => k,
                    None => {
                        entries.push(Entry {
                            info: p.clone(),
                            scheme: false,
                            roles: Vec::new(),
                            value: p.default,
                            source: Source::File,
                        });
                        entries.len() - 1
                    }
                };
                let own = p.owner == u.name();
                for r in &roles {
                    if own && !entries[index].roles.contains(r) {
                        entries[index].roles.push(r);
                    } else if !own {
                        imported.push((index, r));
                    }
                }
            }
        }
        for (index, role) in imported {
            if entries[index].roles.iter().all(|r| *r == "scheme") {
                entries[index].roles.push(role);
            }
        }
        Table { entries }
    }

    /// Whether the params `hits` are one quantity declared in several files: form files' params
    /// of one name and one doc comment (a material of the user's and the elasticity a contact
    /// law imports both declare `E`, "Young's modulus"). A scheme's param is its own.
    fn one_quantity(&self, hits: &[usize]) -> bool {
        let first = &self.entries[hits[0]];
        hits.len() == 1
            || hits
                .iter()
                .map(|&i| &self.entries[i])
                .all(|e| !e.scheme && !first.scheme && !e.info.doc.is_empty() && e.info.doc == first.info.doc)
    }

    /// The qualified names of the params `hits`, a role offered only where it names one of
    /// them (two contact laws both answer to `contact.gamma0`).
    fn choices(&self, hits: &[usize]) -> Vec<String> {
        let roles = hits.iter().flat_map(|&i| self.entries[i].roles.iter().copied());
        let unique: Vec<&str> =
            roles.filter(|r| hits.iter().filter(|&&i| self.entries[i].roles.contains(r)).count() == 1).collect();
        hits.iter().map(|&i| self.entries[i].choice(&unique)).collect()
    }

    /// The params `name` (`rho`, `material.rho`, `elasticity.rho`) answers to.
    fn answering(&self, name: &str) -> Vec<usize> {
        let (owner, name) = qualified(name);
        (0..self.entries.len()).filter(|&i| self.entries[i].answers(owner, name)).collect()
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

    /// A case's overrides of the scheme's and form files' defaults (a problem's `set`), each
    /// reaching the one param it names; params the files in use do not declare are left alone
    /// (a user's contact law may have no `gamma0`, another scheme no `gam`). A name several
    /// files declare (`rho`: the material's density, generalized-α's ρ∞) is refused, as on the
    /// command line.
    /// `files`: the names of the files a qualifier may name besides those in use (the library's).
    pub fn apply_case(&mut self, overrides: &[(&str, f64)], files: &[&str]) -> Result<(), CaseOverrideError> {
        for (index, &(name, value)) in overrides.iter().enumerate() {
            match self.answering(name).as_slice() {
                [] => {
                    if let (Some(owner), bare) = qualified(name) {
                        let owners = self.entries.iter().map(|e| &*e.info.owner);
                        let known: Vec<&str> =
                            ROLES.iter().copied().chain(files.iter().copied()).chain(owners).collect();
                        let short = |k: &&str| *k == owner || k.strip_prefix("contact_") == Some(owner);
                        if !known.iter().any(short) {
                            let closest = crate::compiler::check::suggest_name(owner, known.iter().copied())
                                .map(|q| format!("{q}.{bare}"));
                            let why = Unnamed::UnknownQualifier(closest);
                            return Err(CaseOverrideError::Unmatched(Unmatched { index, name: name.to_string(), why }));
                        }
                    }
                }
                hits if self.one_quantity(hits) => {
                    for &i in hits {
                        let e = &mut self.entries[i];
                        Self::check(e, value, "the case's override").map_err(CaseOverrideError::Invalid)?;
                        e.value = value;
                        e.source = Source::Case;
                    }
                }
                many => {
                    let why = Unnamed::Several(self.choices(many));
                    return Err(CaseOverrideError::Unmatched(Unmatched { index, name: name.to_string(), why }));
                }
            }
        }
        Ok(())
    }

    /// A pair's `set` values: each reaches the params of that name its law (the file stem
    /// `law`) declares; a name only other files declare is refused, a name no file declares is
    /// left alone (as in [`Table::apply_case`]).
    pub fn apply_scoped(&mut self, overrides: &[(&str, f64)], law: &str) -> Result<(), CaseOverrideError> {
        for (index, &(name, value)) in overrides.iter().enumerate() {
            let hits = self.answering(name);
            let (own, other): (Vec<usize>, Vec<usize>) =
                hits.into_iter().partition(|&i| !self.entries[i].scheme && self.entries[i].info.owner == law);
            if own.is_empty() && !other.is_empty() {
                let mut owners: Vec<String> = other.iter().map(|&i| self.entries[i].info.owner.to_string()).collect();
                owners.dedup();
                let why = match other.iter().any(|&i| self.entries[i].scheme) {
                    true => Unnamed::SchemeParam(owners.join(", ")),
                    false => Unnamed::NotTheLaw { law: law.to_string(), owners },
                };
                return Err(CaseOverrideError::Unmatched(Unmatched { index, name: name.to_string(), why }));
            }
            for i in own {
                let e = &mut self.entries[i];
                Self::check(e, value, "the pair's `set`").map_err(CaseOverrideError::Invalid)?;
                e.value = value;
                e.source = Source::Case;
            }
        }
        Ok(())
    }

    /// The user's settings, each matching exactly one param.
    pub fn apply_user(&mut self, settings: &[Setting]) -> Result<(), CaseError> {
        for (index, s) in settings.iter().enumerate() {
            match self.answering(&s.name).as_slice() {
                [] => return Err(self.unknown(s)),
                hits if self.one_quantity(hits) => {
                    for &i in hits {
                        let e = &mut self.entries[i];
                        Self::check(e, s.value, &s.origin)?;
                        e.value = s.value;
                        e.source = Source::User;
                    }
                }
                many => {
                    let why = Unnamed::Several(self.choices(many));
                    let a = Unmatched { index, name: s.name.clone(), why };
                    return Err(CaseError::Option(format!("{}: {}", s.origin, a.message())));
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

    /// Whether `name` answers to a param of the scheme.
    pub fn is_scheme_param(&self, name: &str) -> bool {
        self.answering(name).iter().any(|&i| self.entries[i].scheme)
    }

    /// The value of the one param `name` answers to (none if no file in use declares it; the
    /// choices if several do).
    pub fn lookup(&self, name: &str) -> Result<Option<f64>, Vec<String>> {
        match self.answering(name).as_slice() {
            [] => Ok(None),
            hits if self.one_quantity(hits) => Ok(Some(self.entries[hits[0]].value)),
            many => Err(self.choices(many)),
        }
    }

    /// Every param's name (qualified where two share it).
    pub fn names(&self) -> Vec<String> {
        self.entries.iter().map(|e| self.display_name(e)).collect()
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
