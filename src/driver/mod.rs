//! The simulation driver's library side: which scheme and form files a run uses (by name from
//! `forms/`, or by path), the value of every param (one default, from its .wf file; a case's
//! overrides; the user's settings), and the binding of the scheme's slots to forms by name.
//! Nothing here names a scheme, a contact law or a param.

mod forms_in_use;
pub use forms_in_use::FormsInUse;
pub mod instance;
pub use instance::Instance;
pub mod interpreted;
pub mod pairs;
pub mod params;
pub mod sources;

use std::path::{Path, PathBuf};

use crate::error::CaseError;
use crate::forms::LIBRARY;
use crate::runtime::descriptors::{ParamInfo, SchemeDesc};
use crate::runtime::fem::bound::BoundForm;

use crate::runtime::library::Unit;
use crate::runtime::time::scheme::TimeScheme;

pub use params::{ParamValue, Setting};
pub use sources::FormSource;

/// A form bound to the slot name a scheme applies it by.
pub type Slot<'s, 'm> = (&'s str, Box<dyn BoundForm + 'm>);

/// The methods of a run as the user named them (CLI flags or case-file keys): the scheme, the
/// contact law, the material and extra form files, by name or path, the param settings, and the
/// step guard. [`FilesInUse::resolve`] finds the files and gives every param its value.
#[derive(Clone, Debug, PartialEq)]
pub struct Methods {
    /// A scheme of `forms/schemes/` by name, or a .wf file.
    pub scheme: String,
    /// A contact law of `forms/` by name (`nitsche` for `contact_nitsche`), or a .wf file.
    pub contact: String,
    /// The material's form file (by name or path).
    pub material: String,
    /// Extra form files whose slots the scheme applies.
    pub forms: Vec<PathBuf>,
    /// Form files the run writes itself (a problem's `neumann` loads): a name and the text,
    /// interpreted after the others.
    pub generated: Vec<(String, String)>,
    /// Units compiled by the user's own crate (`forms!(...)::UNIT`): their schemes and form
    /// files are found by name before the library's.
    pub compiled: Vec<&'static Unit>,
    /// Param values set by the user, in order (a later setting of a param wins).
    pub params: Vec<Setting>,
    /// A problem's contact pairs grouped by law, when they are not all bound to `contact`
    /// (a pair with a law or params of its own, or an obstacle's law in `contact`).
    pub pairs: Vec<pairs::PairLaw>,
    /// Step cuts and the energy check.
    pub guard: crate::guard::Guard,
}

impl Default for Methods {
    fn default() -> Self {
        let d = &crate::settings::get().defaults;
        Methods {
            scheme: d.scheme.clone(),
            contact: d.contact.clone(),
            material: d.material.clone(),
            forms: Vec::new(),
            generated: Vec::new(),
            compiled: Vec::new(),
            params: Vec::new(),
            pairs: Vec::new(),
            guard: Default::default(),
        }
    }
}

impl Methods {
    /// Adds a user setting `name = value` (`name` may be qualified: `unit.name`).
    pub fn set(mut self, name: &str, value: f64) -> Self {
        self.params.push(Setting { name: name.into(), value, origin: "options".into() });
        self
    }

    /// Adds `name = value` before the settings already made, which override it: a caller's
    /// default (`verify` runs the disc at h = 2 unless the user's `--param h=…` says otherwise).
    pub fn set_default(mut self, name: &str, value: f64) -> Self {
        self.params.insert(0, Setting { name: name.into(), value, origin: "options".into() });
        self
    }
}

/// What a run holds its scheme to ([`FilesInUse::scheme_energy`]); empty for a scheme compiled
/// by a crate of its own (there is no source to read).
#[derive(Default)]
pub struct SchemeEnergy {
    /// The numeric claims at the params in use (`claim cfl = ...`).
    pub claims: Vec<(String, f64)>,
    pub law: Option<crate::compiler::scheme::EnergyLaw>,
    /// The energy identity derived from the file, when there is one.
    pub identity: Option<SchemeIdentity>,
}

/// A scheme's derived energy identity, with its file and the params in use.
pub struct SchemeIdentity {
    pub ir: crate::compiler::scheme::SchemeIr,
    pub identity: crate::compiler::scheme::energy::classify::Identity,
    pub params: Vec<f64>,
}

/// A scheme, compiled or loaded from a file.
pub enum SchemeSource {
    Compiled(&'static crate::runtime::library::SchemeUnit),
    Interpreted(Box<interpreted::Interpreted>),
}

impl SchemeSource {
    pub fn desc(&self) -> &SchemeDesc {
        match self {
            SchemeSource::Compiled(u) => u.desc,
            SchemeSource::Interpreted(i) => &i.desc,
        }
    }

    pub fn params(&self) -> &[ParamInfo] {
        match self {
            SchemeSource::Compiled(u) => u.params,
            SchemeSource::Interpreted(i) => &i.params,
        }
    }

    pub fn interpreted(&self) -> bool {
        matches!(self, SchemeSource::Interpreted(_))
    }
}

fn is_path(s: &str) -> bool {
    s.ends_with(".wf") || s.contains('/')
}

/// The library's units, for `list` and lookups.
pub fn library() -> &'static [&'static Unit] {
    LIBRARY
}

/// The user's compiled units, then the library's.
fn units(methods: &Methods) -> impl Iterator<Item = &'static Unit> + '_ {
    methods.compiled.iter().copied().chain(LIBRARY.iter().copied())
}

/// A compiled scheme by name (`hht-imex` finds `hht_imex`).
fn library_scheme(methods: &Methods) -> Option<&'static crate::runtime::library::SchemeUnit> {
    let name = methods.scheme.replace('-', "_");
    units(methods).flat_map(|u| u.schemes.iter()).find(|s| s.name == name)
}

/// A compiled form file by name; `prefix_name` also matches (`nitsche` → `contact_nitsche`).
fn library_forms(methods: &Methods, name: &str, prefix: &str) -> Option<&'static Unit> {
    let name = name.replace('-', "_");
    let found = |n: &str| units(methods).find(|u| u.forms.is_some() && u.name == n);
    found(&name).or_else(|| found(&format!("{prefix}{name}")))
}

fn scheme_names(methods: &Methods) -> Vec<&'static str> {
    units(methods).flat_map(|u| u.schemes.iter()).map(|s| s.name).collect()
}

/// Names of the library's contact laws (the files providing a `contact` slot), short form.
pub fn contact_names() -> Vec<&'static str> {
    LIBRARY
        .iter()
        .filter(|u| u.forms.is_some_and(|f| f.slots.iter().any(|s| s.name == "contact")))
        .map(|u| u.name.strip_prefix("contact_").unwrap_or(u.name))
        .collect()
}

/// Names of the library's contact laws between two bodies (`forms/pairs/`, by file stem).
pub fn pair_names() -> Vec<&'static str> {
    sources::pair_names()
}

/// Names of the library's frictional contact laws (those that also provide `friction_work`),
/// short form.
pub fn frictional_contact_names() -> Vec<&'static str> {
    let frictional = |name: &str| {
        LIBRARY.iter().any(|u| {
            u.name.strip_prefix("contact_").unwrap_or(u.name) == name
                && u.forms.is_some_and(|f| f.slots.iter().any(|s| s.name == "friction_work"))
        })
    };
    contact_names().into_iter().filter(|n| frictional(n)).collect()
}

/// Whether a file of the library (a scheme or a form file) declares a param of that name.
pub fn library_declares(name: &str) -> bool {
    LIBRARY.iter().any(|u| {
        u.schemes
            .iter()
            .flat_map(|s| s.params.iter())
            .chain(u.forms.iter().flat_map(|f| f.params.iter()))
            .any(|p| p.name == name)
    })
}

/// Whether a form file of the library provides a functional of that name (part of the
/// documented contract of some law: `contact_trial`, `friction_work`).
pub fn library_functional(name: &str) -> bool {
    LIBRARY.iter().filter_map(|u| u.forms).any(|f| f.slots.iter().any(|s| s.functional && s.name == name))
}

/// Every scheme of the library, by name.
pub fn all_schemes() -> Vec<&'static str> {
    scheme_names(&Methods::default())
}

/// The library's schemes that declare an `estimate` (that can run with adaptive steps).
pub fn estimating_schemes() -> Vec<&'static str> {
    all_schemes()
        .into_iter()
        .filter(|&name| {
            let methods = Methods { scheme: name.to_string(), ..Methods::default() };
            library_scheme(&methods).is_some_and(|u| u.desc.estimate.is_some())
        })
        .collect()
}

fn unknown(what: &str, name: &str, known: &[&str]) -> CaseError {
    let hint = crate::compiler::check::suggest_name(name, known.iter().copied())
        .map_or(String::new(), |s| format!("; did you mean `{s}`?"));
    CaseError::Option(format!(
        "no {what} `{name}` in the library (known: {}){hint}; or give a .wf file",
        known.join(", ")
    ))
}

/// Resolves the scheme of a run's methods.
pub fn scheme(methods: &Methods) -> Result<SchemeSource, CaseError> {
    if is_path(&methods.scheme) {
        let path = Path::new(&methods.scheme);
        return interpreted::load(path, None).map(|i| SchemeSource::Interpreted(Box::new(i)));
    }
    library_scheme(methods)
        .map(SchemeSource::Compiled)
        .ok_or_else(|| unknown("scheme", &methods.scheme, &scheme_names(methods)))
}

/// The role a form file imports to read the run's material (`import material = elasticity`:
/// a Nitsche law's traction is the material's stress).
pub const MATERIAL_ROLE: &str = "material";

/// A compiled unit as it runs with the material `material`: as compiled, unless it imports
/// the material's role and the run binds another file to it. Then as compiled for that file,
/// if the library's build did (`forms::BOUND`: its laws with each of its files that can stand
/// in for their roles), else compiled again, at run time, with that file.
fn with_roles(u: &'static Unit, material: &FormSource, roles: &[(String, PathBuf)]) -> Result<FormSource, CaseError> {
    let compiled_for = |v: &Unit| {
        v.forms.is_none_or(|f| {
            f.roles.iter().all(|(role, read)| {
                *role != MATERIAL_ROLE || matches!(material, FormSource::Compiled(m) if m.name == *read)
            })
        })
    };
    if let Some(v) = std::iter::once(u).chain(crate::forms::BOUND.iter().copied()).find(|v| *v == u && compiled_for(v))
    {
        return Ok(FormSource::Compiled(v));
    }
    let mut i = interpret_bound(Path::new(u.file), material, roles)?;
    i.rebound = Some(material.file().to_string());
    Ok(FormSource::Interpreted(Box::new(i)))
}

/// A form file read and compiled at run time with the run's files bound to its roles.
fn interpret_bound(
    path: &Path,
    material: &FormSource,
    roles: &[(String, PathBuf)],
) -> Result<sources::Interpreted, CaseError> {
    sources::interpret(path, roles).map_err(|e| {
        let context = format!(
            "{} with the run's material `{}` bound to its `import {MATERIAL_ROLE} = ...`:\n",
            path.display(),
            material.file()
        );
        CaseError::Wf(crate::compiler::Failure { rendered: context + &e.rendered, ..e })
    })
}

/// The form files of a run's methods (material, contact law, extras; the contact law's index).
pub fn form_units(methods: &Methods) -> Result<(Vec<FormSource>, usize), CaseError> {
    form_units_with_pairs(methods).map(|(units, contact, _)| (units, contact))
}

/// As [`form_units`], with the index of each pair group's law.
fn form_units_with_pairs(methods: &Methods) -> Result<(Vec<FormSource>, usize, Vec<usize>), CaseError> {
    let form_files: Vec<&str> = units(methods).filter(|u| u.forms.is_some()).map(|u| u.name).collect();
    let material = match &methods.material {
        name if is_path(name) => match library_file(Path::new(name)) {
            Some(u) => FormSource::Compiled(u),
            None => sources::interpret(Path::new(name), &[])
                .map(|i| FormSource::Interpreted(Box::new(i)))
                .map_err(CaseError::Wf)?,
        },
        name => library_forms(methods, name, "")
            .map(FormSource::Compiled)
            .ok_or_else(|| unknown("form file", name, &form_files))?,
    };
    let roles = vec![(MATERIAL_ROLE.to_string(), PathBuf::from(material.file()))];
    let pick = |name: &str, prefix: &str, what: &str, known: &[&str]| -> Result<FormSource, CaseError> {
        if is_path(name) {
            let path = Path::new(name);
            if let Some(u) = library_file(path) {
                return with_roles(u, &material, &roles);
            }
            return sources::interpret(path, &roles)
                .map(|i| FormSource::Interpreted(Box::new(i)))
                .map_err(CaseError::Wf);
        }
        match library_forms(methods, name, prefix) {
            Some(u) => with_roles(u, &material, &roles),
            None => match sources::library_pair(name) {
                Some(pair) => pair.map(|i| FormSource::Interpreted(Box::new(i))).map_err(CaseError::Wf),
                None => Err(unknown(what, name, known)),
            },
        }
    };
    let contact = pick(&methods.contact, "contact_", "contact law", &contact_names())?;
    let extras: Vec<FormSource> = methods
        .forms
        .iter()
        .map(|f| pick(&f.display().to_string(), "", "form file", &form_files))
        .collect::<Result<_, _>>()?;
    // Each group's law, read once.
    let mut laws: Vec<(&str, Option<FormSource>)> = Vec::new();
    for g in &methods.pairs {
        let earlier = laws.iter().any(|(law, _)| *law == g.law);
        laws.push((&g.law, if earlier { None } else { Some(pick(&g.law, "", "pair law", &pair_names())?) }));
    }
    let mut units = vec![material];
    // A file already in use (the material bound as a contact law too, a pair law twice) is
    // one unit.
    let place = |units: &mut Vec<FormSource>, u: FormSource| match units
        .iter()
        .position(|v| v.name() == u.name() && v.file() == u.file())
    {
        Some(i) => i,
        None => {
            units.push(u);
            units.len() - 1
        }
    };
    let contact_index = place(&mut units, contact);
    let mut groups = Vec::new();
    for (law, unit) in laws {
        groups.push(match unit {
            Some(u) => place(&mut units, u),
            None => groups[methods.pairs.iter().position(|g| g.law == law).expect("an earlier group")],
        });
    }
    for u in extras {
        place(&mut units, u);
    }
    for (name, text) in &methods.generated {
        let u = sources::interpret_text(name, text).map_err(CaseError::Wf)?;
        units.push(FormSource::Interpreted(Box::new(u)));
    }
    Ok((units, contact_index, groups))
}

fn apply_overrides(
    table: &mut params::Table,
    overrides: &[(&str, f64)],
    locate: &dyn Fn(&params::Unmatched) -> CaseError,
) -> Result<(), CaseError> {
    let files: Vec<&str> = LIBRARY.iter().map(|u| u.name).chain(pair_names()).collect();
    table.apply_case(overrides, &files).map_err(|e| match e {
        params::CaseOverrideError::Invalid(e) => e,
        params::CaseOverrideError::Unmatched(a) => locate(&a),
    })
}

fn unlocated(a: &params::Unmatched) -> CaseError {
    CaseError::Option(format!("the case's override: {}", a.message()))
}

/// A path that is one of the library's own files (compiled already).
fn library_file(path: &Path) -> Option<&'static Unit> {
    let stem = path.file_stem()?.to_string_lossy().into_owned();
    let here = crate::library_dir::forms().join(format!("{stem}.wf"));
    let same = std::fs::canonicalize(path).ok()? == std::fs::canonicalize(here).ok()?;
    if same { LIBRARY.iter().copied().find(|u| u.name == stem && u.forms.is_some()) } else { None }
}

/// The files in use of a run: its scheme and form files, found (compiled, or read and
/// interpreted), with the value of every param; and its step guard.
pub struct FilesInUse {
    pub scheme: SchemeSource,
    /// The form files and every param's value (the scheme's included).
    pub forms: FormsInUse,
    pub guard: crate::guard::Guard,
}

impl FilesInUse {
    /// Resolves a run's methods: files, then params (file defaults < `overrides` of the case < the
    /// user's settings).
    pub fn resolve(methods: &Methods, overrides: &[(&str, f64)]) -> Result<FilesInUse, CaseError> {
        Self::resolve_located(methods, overrides, &unlocated)
    }

    /// As [`FilesInUse::resolve`], with `locate` saying where an ambiguous override was written
    /// (a problem's `set` line).
    pub fn resolve_located(
        methods: &Methods,
        overrides: &[(&str, f64)],
        locate: &dyn Fn(&params::Unmatched) -> CaseError,
    ) -> Result<FilesInUse, CaseError> {
        let scheme = scheme(methods)?;
        let forms = FormsInUse::new(Some(&scheme), methods, overrides, locate)?;
        pairs::contact_slots_agree(&scheme, &forms)?;
        Ok(FilesInUse { scheme, forms, guard: methods.guard })
    }

    /// The params of each body (its name, and its `set` values as overrides): the files'
    /// defaults, the problem's `overrides`, the body's, then the user's settings. A body's
    /// values reach the form files' params; a scheme's param is the problem's (an error).
    pub fn set_bodies(
        &mut self,
        methods: &Methods,
        overrides: &[(&str, f64)],
        bodies: &[(String, Vec<(&str, f64)>)],
        locate: &dyn Fn(&str, &params::Unmatched) -> CaseError,
    ) -> Result<(), CaseError> {
        let (units, contact) = (&self.forms.units, self.forms.contact_units());
        let mut tables = Vec::new();
        for (name, own) in bodies {
            for (index, (param, _)) in own.iter().enumerate() {
                if self.forms.params.is_scheme_param(param) {
                    let why = params::Unnamed::SchemeParam(self.scheme_name().to_string());
                    return Err(locate(name, &params::Unmatched { index, name: param.to_string(), why }));
                }
            }
            let mut table = params::Table::new(Some(&self.scheme), units, &contact);
            apply_overrides(&mut table, overrides, &unlocated)?;
            apply_overrides(&mut table, own, &|a| locate(name, a))?;
            table.apply_user(&methods.params)?;
            tables.push((name.clone(), table));
        }
        self.forms.bodies = tables;
        Ok(())
    }

    /// The form files of a run's methods and their params, without a scheme.
    pub fn resolve_forms(methods: &Methods, overrides: &[(&str, f64)]) -> Result<FormsInUse, CaseError> {
        FormsInUse::new(None, methods, overrides, &unlocated)
    }

    /// The scheme with its param values.
    pub fn time_scheme(&self) -> Result<Box<dyn TimeScheme>, CaseError> {
        let values = self.forms.params.scheme_values(self.scheme.params());
        let made = match &self.scheme {
            SchemeSource::Compiled(u) => (u.make)(&values),
            SchemeSource::Interpreted(i) => i.instance(&values),
        };
        made.map_err(|e| CaseError::Option(e.to_string()))
    }

    /// The files of this run that were compiled at run time (given by path, not in the library).
    pub fn interpreted(&self) -> Vec<String> {
        let scheme = match &self.scheme {
            SchemeSource::Interpreted(i) => Some(i.file.clone()),
            SchemeSource::Compiled(_) => None,
        };
        let own = |u: &FormSource| matches!(u, FormSource::Interpreted(i) if !i.generated && !i.library && i.rebound.is_none());
        let forms = self.forms.units.iter().filter(|u| own(u)).map(|u| u.file().to_string());
        scheme.into_iter().chain(forms).collect()
    }

    /// The library's files compiled again at run time for the run's material (`import material
    /// = ...` bound to another file than the one compiled in): the file and the material.
    pub fn rebound(&self) -> Vec<(String, String)> {
        let rebound = |u: &FormSource| match u {
            FormSource::Interpreted(i) => i.rebound.clone().map(|m| (i.file.clone(), m)),
            FormSource::Compiled(_) => None,
        };
        self.forms.units.iter().filter_map(rebound).collect()
    }

    pub fn scheme_name(&self) -> &str {
        &self.scheme.desc().name
    }

    /// What the scheme's file claims (`claim order = 2`, `claim rho_inf = rho`), at the param
    /// values in use.
    pub fn scheme_claims(&self) -> Result<Vec<(String, f64)>, CaseError> {
        let params = self.forms.params.scheme_values(self.scheme.params());
        Ok(self.scheme_ir()?.map_or_else(Vec::new, |ir| ir.claims_at(&params)))
    }

    /// The energy law the scheme's file claims (`claim energy = conserving`), if it does.
    pub fn scheme_energy_law(&self) -> Result<Option<crate::compiler::scheme::EnergyLaw>, CaseError> {
        Ok(self.scheme_ir()?.and_then(|ir| ir.energy))
    }

    /// What the scheme's energy identity proves of the law its file claims, at the params in
    /// use (`verify --scheme` shows it beside the law it samples).
    pub fn scheme_energy_proof(&self) -> Result<Option<String>, CaseError> {
        let params = self.forms.params.scheme_values(self.scheme.params());
        Ok(self.scheme_ir()?.and_then(|ir| {
            let law = ir.energy?;
            Some(crate::compiler::scheme::energy::claim::verdict(&ir, law, &params))
        }))
    }

    /// From one reading of the scheme's file: its numeric claims at the params in use, the law
    /// a run holds the scheme to there (the claim where its energy identity proves it there or
    /// does not decide, else the law the identity proves, or none), and the identity itself.
    pub fn scheme_energy(&self) -> Result<SchemeEnergy, CaseError> {
        use crate::compiler::scheme::energy::{claim, classify::Identity};
        let params = self.forms.params.scheme_values(self.scheme.params());
        let Some(ir) = self.scheme_ir()? else { return Ok(SchemeEnergy::default()) };
        let identity = Identity::derive(&ir).ok();
        let law = ir.energy.and_then(|claimed| claim::law_by(identity.as_ref(), claimed, &params));
        let claims = ir.claims_at(&params);
        let identity = identity.map(|identity| SchemeIdentity { ir, identity, params });
        Ok(SchemeEnergy { claims, law, identity })
    }

    /// The scheme's compiled file (none for a scheme compiled by a crate of its own: there is
    /// no source here).
    fn scheme_ir(&self) -> Result<Option<crate::compiler::scheme::SchemeIr>, CaseError> {
        use crate::compiler::{MemLoader, check_path};
        let name = self.scheme_name();
        let programs = match &self.scheme {
            // The library file that declares it.
            SchemeSource::Compiled(_) => crate::forms::SCHEME_SOURCES
                .iter()
                .filter(|(_, text)| text.contains(&format!("scheme {name}")))
                .map(|(stem, text)| {
                    let path = format!("forms/schemes/{stem}.wf");
                    check_path(Path::new(&path), &MemLoader::default().with(&path, *text))
                })
                .collect::<Vec<_>>(),
            SchemeSource::Interpreted(i) => vec![check_path(Path::new(&i.file), &sources::LibraryLoader)],
        };
        for compiled in programs {
            let (program, _) = compiled.map_err(CaseError::Wf)?;
            if let Some(ir) = program.schemes.into_iter().find(|s| s.name == name) {
                return Ok(Some(ir));
            }
        }
        Ok(None)
    }

    /// The forms the scheme applies, bound; errors name the slot's declaration.
    pub fn scheme_forms<'m>(&self, inst: &mut Instance<'m>) -> Result<Vec<Slot<'_, 'm>>, CaseError> {
        self.scheme_forms_with(inst, Vec::new())
    }

    /// As [`FilesInUse::scheme_forms`], with some slots bound to the given forms instead.
    pub fn scheme_forms_with<'s, 'm>(
        &'s self,
        inst: &mut Instance<'m>,
        mut given: Vec<Slot<'s, 'm>>,
    ) -> Result<Vec<Slot<'s, 'm>>, CaseError> {
        let desc = self.scheme.desc();
        let mut out = Vec::new();
        for slot in desc.uses.iter() {
            if let Some(i) = given.iter().position(|(name, _)| *name == slot.name) {
                out.push(given.swap_remove(i));
                continue;
            }
            let provided = || {
                let list: Vec<String> = self
                    .forms
                    .units
                    .iter()
                    .map(|u| {
                        let names: Vec<&str> = u.slots().iter().map(|s| &*s.name).collect();
                        format!("{}: {}", u.file(), names.join(", "))
                    })
                    .collect();
                list.join("; ")
            };
            let Some(form) = inst.take_form(&slot.name) else {
                return Err(CaseError::Option(format!(
                    "scheme `{}` applies slot `{}` ({}), which none of the form files in use provides ({}); add one with --forms FILE.wf",
                    desc.name,
                    slot.name,
                    slot.declared,
                    provided()
                )));
            };
            if form.fields() != slot.fields {
                return Err(CaseError::Option(format!(
                    "scheme `{}` applies slot `{}` to {} time level(s) ({}), but form `{}` takes {}",
                    desc.name,
                    slot.name,
                    slot.fields,
                    slot.declared,
                    form.name(),
                    form.fields()
                )));
            }
            out.push((&*slot.name, form));
        }
        Ok(out)
    }
}
