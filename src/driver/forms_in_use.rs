//! The form files in use of a run with their params, and their forms bound to a mesh: each
//! file's, per body with the body's params, each pair group's law bound to its pairs.

use super::instance::{Instance, Provided, add_to_slot};
use super::{FormSource, Methods, SchemeSource, apply_overrides, form_units_with_pairs, pairs, params};
use crate::error::CaseError;
use crate::forms::LIBRARY;
use crate::runtime::fem::kernel::Coef;
use crate::runtime::library::Binding;

/// The form files in use of a run (material, contact law, extras), with the value of every
/// param (the scheme's included).
pub struct FormsInUse {
    /// Material, contact law, pair laws, extra forms.
    pub units: Vec<FormSource>,
    /// Index of the contact law in `units` (an obstacle's, else the first pair group's).
    pub contact: usize,
    /// The problem's pairs grouped by law, when they are not all bound to `contact`.
    pub pairs: Vec<pairs::PairGroup>,
    pub params: params::Table,
    /// The params of each body of a problem with several, by the body's name: its `set` values
    /// over the problem's, the user's settings over both.
    pub bodies: Vec<(String, params::Table)>,
}

impl FormsInUse {
    /// The form files of `methods` with their params: the files' defaults, `overrides`, the
    /// user's settings.
    pub(super) fn new(
        scheme: Option<&SchemeSource>,
        methods: &Methods,
        overrides: &[(&str, f64)],
        locate: &dyn Fn(&params::Unmatched) -> CaseError,
    ) -> Result<FormsInUse, CaseError> {
        let (units, contact, laws) = form_units_with_pairs(methods)?;
        let pairs = methods
            .pairs
            .iter()
            .zip(laws)
            .map(|(g, unit)| pairs::PairGroup {
                label: g.label.clone(),
                pairs: g.pairs.clone(),
                unit,
                params: None,
                bodies: Vec::new(),
            })
            .collect();
        let mut forms =
            FormsInUse { units, contact, pairs, params: params::Table::new(None, &[], &[]), bodies: Vec::new() };
        let mut table = params::Table::new(scheme, &forms.units, &forms.contact_units());
        apply_overrides(&mut table, overrides, locate)?;
        table.apply_user(&methods.params)?;
        forms.params = table;
        Ok(forms)
    }

    /// The contact laws' indices in `units`: the run's, and each pair group's.
    pub fn contact_units(&self) -> Vec<usize> {
        let mut out = vec![self.contact];
        for g in &self.pairs {
            if !out.contains(&g.unit) {
                out.push(g.unit);
            }
        }
        out
    }

    /// Each body's params whose values differ from the problem's, by `BODY.name`.
    pub fn body_values(&self) -> std::collections::BTreeMap<String, params::ParamValue> {
        let problem = self.params.values();
        let mut out = std::collections::BTreeMap::new();
        for (body, table) in &self.bodies {
            for (name, p) in table.values() {
                if problem.get(&name).is_none_or(|q| q.value.to_bits() != p.value.to_bits()) {
                    out.insert(format!("{body}.{name}"), p);
                }
            }
        }
        out
    }

    /// Each pair group's params that differ from the problem's, by `OWN-FACING.name`.
    pub fn pair_values(&self) -> std::collections::BTreeMap<String, params::ParamValue> {
        pairs::pair_values(&self.params.values(), &self.pairs, &self.units)
    }

    /// The params in effect, `name = value, ...`, then the bodies' and the pairs' own.
    pub fn params_text(&self) -> String {
        let all = self.params.values().into_iter().chain(self.body_values()).chain(self.pair_values());
        all.map(|(name, p)| format!("{name} = {}", p.value)).collect::<Vec<_>>().join(", ")
    }

    /// The contact laws' names (file stems): `contact_penalty + pair_nitsche` when an obstacle
    /// and pairs, or pairs of several laws, are in contact.
    pub fn contact_name(&self) -> String {
        let names: Vec<&str> = self.contact_units().into_iter().map(|i| self.units[i].name()).collect();
        names.join(" + ")
    }

    /// Every form and functional of the files in use, bound to a mesh: to each of its bodies
    /// with the body's params, and summed over them, when it has several.
    pub fn instantiate<'m>(
        &self,
        coefs: &dyn Fn(&str) -> Option<Coef>,
        binding: &Binding<'m>,
    ) -> Result<Instance<'m>, CaseError> {
        if binding.bodies.is_empty() {
            return self.instantiate_with(&self.params, None, coefs, binding);
        }
        let mut each = Vec::new();
        for body in binding.bodies {
            let params = self.bodies.iter().find(|(name, _)| *name == body.name).map_or(&self.params, |(_, t)| t);
            each.push(self.instantiate_with(params, Some(&body.name), coefs, &binding.body(body))?);
        }
        Ok(Instance::over_bodies(each))
    }

    /// The files' forms with the param values of `params` (those of `body`, if named); a pair
    /// group's law bound to its pairs, with its own values if it has some.
    fn instantiate_with<'m>(
        &self,
        params: &params::Table,
        body: Option<&str>,
        coefs: &dyn Fn(&str) -> Option<Coef>,
        binding: &Binding<'m>,
    ) -> Result<Instance<'m>, CaseError> {
        let mut slots = Vec::new();
        let contact = self.contact_units();
        for (i, unit) in self.units.iter().enumerate() {
            let groups: Vec<&pairs::PairGroup> = self.pairs.iter().filter(|g| g.unit == i).collect();
            if groups.is_empty() {
                self.make(unit, params, "", coefs, binding, contact.contains(&i), &mut slots)?;
            }
            for g in groups {
                let table = g.table(body).unwrap_or(params);
                let label = format!("pair {}: ", g.label);
                self.make(unit, table, &label, coefs, &binding.with_pairs(&g.pairs), true, &mut slots)?;
            }
        }
        Ok(Instance { slots })
    }

    /// One file's forms, added to their slots; errors start with `label`.
    #[allow(clippy::too_many_arguments)]
    fn make<'m>(
        &self,
        unit: &FormSource,
        params: &params::Table,
        label: &str,
        coefs: &dyn Fn(&str) -> Option<Coef>,
        binding: &Binding<'m>,
        contact: bool,
        slots: &mut Vec<Provided<'m>>,
    ) -> Result<(), CaseError> {
        let values = params.unit_values(unit.params());
        let made = unit.make(&values, coefs, binding).map_err(|e| {
            let hint = match &e {
                crate::runtime::library::LibraryError::MissingCoef { name, .. } => provided_coefs(coefs, name),
                _ => String::new(),
            };
            // Errors located in the file already (a region, a tangential part) need no prefix.
            match &e {
                crate::runtime::library::LibraryError::MissingRegion { .. } => {
                    CaseError::Option(format!("{label}{e}{hint}"))
                }
                crate::runtime::library::LibraryError::NoTangentSpace { .. } => {
                    CaseError::NoTangentSpace(format!("{label}{e}"))
                }
                _ => CaseError::Option(format!("{label}{}: {e}{hint}", unit.file())),
            }
        })?;
        for (name, form) in made {
            add_to_slot(slots, name, form, unit.file(), contact)?;
        }
        Ok(())
    }
}

/// The coefs a case provides, among those the library's files declare, with the closest to
/// `missing`: "; the case provides f, g, nc; did you mean `g`?".
fn provided_coefs(coefs: &dyn Fn(&str) -> Option<Coef>, missing: &str) -> String {
    let mut names: Vec<&str> =
        LIBRARY.iter().filter_map(|u| u.forms).flat_map(|f| f.coefs.iter().map(|c| &*c.name)).collect();
    names.sort_unstable();
    names.dedup();
    names.retain(|n| coefs(n).is_some());
    if names.is_empty() {
        return String::new();
    }
    let hint = crate::compiler::check::suggest_name(missing, names.iter().copied())
        .map_or(String::new(), |s| format!("; did you mean `{s}`?"));
    format!("; the case provides {}{hint}", names.join(", "))
}
