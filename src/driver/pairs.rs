//! A problem's contact pairs grouped by law. The pairs without a block of their own share the
//! run's pair law; a pair with a block (`contact A with B { bind contact = LAW  set p = v }`) is
//! a group of its own, with its law and its params (its `set` values over the problem's and its
//! bodies', the user's over them). Each group's law is bound to its pairs only.

use std::collections::BTreeMap;

use super::params::{self, CaseOverrideError, Table, Unmatched, Unnamed};
use super::{
    FilesInUse, FormSource, FormsInUse, Methods, SchemeSource, is_path, library_file, library_forms, sources, unknown,
};
use crate::error::CaseError;

/// Pairs bound to one law, as the run's methods name it.
#[derive(Clone, Debug, PartialEq)]
pub struct PairLaw {
    /// How messages name the group: `bottom with top`, or `the problem's pairs`.
    pub label: String,
    /// Indices into the problem's pairs.
    pub pairs: Vec<usize>,
    /// A library pair law by name, or a path.
    pub law: String,
    /// One pair with a block of its own (which may set its params).
    pub own: bool,
}

/// A group of pairs bound to one of the run's form files, with its params when its block sets
/// any.
pub struct PairGroup {
    pub label: String,
    /// Indices into the problem's pairs (and the binding's).
    pub pairs: Vec<usize>,
    /// Its law's index among the files in use.
    pub unit: usize,
    /// Its params, when its block sets some: the problem's table with the pair's values and
    /// the user's over them (`None`: the problem's and the bodies' tables).
    pub params: Option<Table>,
    /// The same, over each body's table.
    pub bodies: Vec<(String, Table)>,
}

impl PairGroup {
    /// The table its law is made with on `body` (`None`: the caller's).
    pub fn table(&self, body: Option<&str>) -> Option<&Table> {
        let own = body.and_then(|b| self.bodies.iter().find(|(name, _)| name == b).map(|(_, t)| t));
        own.or(self.params.as_ref())
    }
}

/// Whether the contact law `name` (a library name or a path) is a pair law (it reads
/// `opposite`) rather than an obstacle's.
pub fn names_pair_law(methods: &Methods, name: &str) -> Result<bool, CaseError> {
    if is_path(name) {
        let path = std::path::Path::new(name);
        if library_file(path).is_some() {
            return Ok(false);
        }
        // Checked without its warnings: the run reads it again and prints them then.
        let (program, _) = crate::compiler::check_path(path, &sources::LibraryLoader).map_err(CaseError::Wf)?;
        return Ok(crate::interpret::Library::new(&program).is_pair_law());
    }
    if library_forms(methods, name, "contact_").is_some() {
        return Ok(false);
    }
    if sources::pair_names().contains(&name) {
        return Ok(true);
    }
    let known: Vec<&str> = super::contact_names().into_iter().chain(sources::pair_names()).collect();
    Err(unknown("contact law", name, &known))
}

/// Every contact law of a run (an obstacle's, the pairs') provides each contact slot the
/// scheme applies that one of them does: a slot only some provide would leave the others'
/// contact out of the run (the hybrid scheme's `hybrid_contact`, which pair laws lack).
pub fn contact_slots_agree(scheme: &SchemeSource, forms: &FormsInUse) -> Result<(), CaseError> {
    let contact = forms.contact_units();
    let provides = |i: usize, slot: &str| forms.units[i].slots().iter().any(|s| &*s.name == slot && !s.functional);
    let desc = scheme.desc();
    for slot in desc.uses.iter() {
        let (with, without): (Vec<usize>, Vec<usize>) = contact.iter().partition(|&&i| provides(i, &slot.name));
        if let (Some(&a), Some(&b)) = (with.first(), without.first()) {
            let by = |i: usize| {
                let pairs: Vec<&str> = forms.pairs.iter().filter(|g| g.unit == i).map(|g| g.label.as_str()).collect();
                let to = if pairs.is_empty() { String::new() } else { format!(" (bound to {})", pairs.join(", ")) };
                format!("`{}`{to}", forms.units[i].name())
            };
            return Err(CaseError::Option(format!(
                "scheme `{}` applies slot `{}` ({}), which contact law {} provides and {} does not: its contact would be left out; use a scheme whose slots every contact law in use provides",
                desc.name,
                slot.name,
                slot.declared,
                by(a),
                by(b)
            )));
        }
    }
    Ok(())
}

impl FilesInUse {
    /// The params of the group at `group` from its pair's `set` values (`own`): the problem's
    /// table and each body's, with the values (which reach only the params its law declares)
    /// and the user's settings over them.
    pub fn set_pair(
        &mut self,
        methods: &Methods,
        group: usize,
        own: &[(&str, f64)],
        locate: &dyn Fn(&Unmatched) -> CaseError,
    ) -> Result<(), CaseError> {
        let law = self.forms.units[self.forms.pairs[group].unit].name().to_string();
        let scheme = self.scheme_name().to_string();
        let scoped = |table: &Table| -> Result<Table, CaseError> {
            let mut table = table.clone();
            table.apply_scoped(own, &law).map_err(|e| match e {
                CaseOverrideError::Invalid(e) => e,
                CaseOverrideError::Unmatched(a @ Unmatched { why: Unnamed::SchemeParam(_), .. }) => {
                    locate(&Unmatched { why: Unnamed::SchemeParam(scheme.clone()), ..a })
                }
                CaseOverrideError::Unmatched(a) => locate(&a),
            })?;
            table.apply_user(&methods.params)?;
            Ok(table)
        };
        let params = scoped(&self.forms.params)?;
        let bodies =
            self.forms.bodies.iter().map(|(b, t)| Ok((b.clone(), scoped(t)?))).collect::<Result<_, CaseError>>()?;
        let g = &mut self.forms.pairs[group];
        g.params = Some(params);
        g.bodies = bodies;
        Ok(())
    }
}

/// Each group's params that differ from the problem's, by `OWN-FACING.name` (a `-` is in no
/// identifier, so no key is a body's or the problem's).
pub fn pair_values(
    problem: &BTreeMap<String, params::ParamValue>,
    groups: &[PairGroup],
    units: &[FormSource],
) -> BTreeMap<String, params::ParamValue> {
    let mut out = BTreeMap::new();
    for g in groups {
        let Some(table) = &g.params else { continue };
        let law = units[g.unit].name();
        let values = table.values();
        let own: Vec<String> = params::declared_by(&values, law).into_iter().map(|(name, _)| name).collect();
        for (name, p) in values {
            let bare = name.rsplit('.').next().unwrap_or(&name);
            if own.iter().any(|o| o == bare)
                && problem.get(&name).is_none_or(|q| q.value.to_bits() != p.value.to_bits())
            {
                out.insert(format!("{}.{bare}", g.label.replace(" with ", "-")), p);
            }
        }
    }
    out
}
