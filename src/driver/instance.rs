//! The bound forms of a run, by slot: what the form files in use provide once bound to a mesh.

use crate::error::CaseError;
use crate::runtime::fem::bound::{BoundForm, BoundFunctional};
use crate::runtime::fem::summed::{Summed, SummedFunctional};
use crate::runtime::library::SlotForm;

/// The bound forms of a run, taken by slot name (and the file that provides each).
pub struct Instance<'m> {
    pub(super) slots: Vec<Provided<'m>>,
}

/// A slot's form or functional, the file (or files, summed) that provide it, and whether those
/// are contact laws (whose functionals of one name add up: an obstacle's and a pair's).
pub(super) struct Provided<'m> {
    pub name: String,
    pub form: SlotForm<'m>,
    pub file: String,
    pub contact: bool,
}

impl<'m> Instance<'m> {
    /// The instances of one set of files on each of several bodies, each slot summed over them
    /// (every body's instance has the same slots, in the same order).
    pub(super) fn over_bodies(each: Vec<Instance<'m>>) -> Instance<'m> {
        let mut slots: Vec<(String, String, bool, Vec<SlotForm<'m>>)> = Vec::new();
        for instance in each {
            for (k, p) in instance.slots.into_iter().enumerate() {
                match slots.get_mut(k) {
                    Some((.., parts)) => parts.push(p.form),
                    None => slots.push((p.name, p.file, p.contact, vec![p.form])),
                }
            }
        }
        let summed = |parts: Vec<SlotForm<'m>>| {
            let (mut forms, mut functionals) = (Vec::new(), Vec::new());
            for part in parts {
                match part {
                    SlotForm::Form(f) => forms.push(f),
                    SlotForm::Functional(f) => functionals.push(f),
                }
            }
            match forms.is_empty() {
                false => SlotForm::Form(Box::new(Summed::over_bodies(forms))),
                true => SlotForm::Functional(Box::new(SummedFunctional::over_bodies(functionals))),
            }
        };
        let slots =
            slots.into_iter().map(|(name, file, contact, parts)| Provided { name, form: summed(parts), file, contact });
        Instance { slots: slots.collect() }
    }

    /// Takes the form of a slot (a functional or a missing slot: `None`).
    pub fn take_form(&mut self, name: &str) -> Option<Box<dyn BoundForm + 'm>> {
        let i = self.slots.iter().position(|p| p.name == name && matches!(p.form, SlotForm::Form(_)))?;
        match self.slots.remove(i).form {
            SlotForm::Form(f) => Some(f),
            SlotForm::Functional(_) => unreachable!("matched a form"),
        }
    }

    /// Whether a file in use provides the functional `name` (and it is not taken yet).
    pub fn provides_functional(&self, name: &str) -> bool {
        self.slots.iter().any(|p| p.name == name && matches!(p.form, SlotForm::Functional(_)))
    }

    /// Takes the functional of a slot.
    pub fn take_functional(&mut self, name: &str) -> Option<Box<dyn BoundFunctional + 'm>> {
        let i = self.slots.iter().position(|p| p.name == name && matches!(p.form, SlotForm::Functional(_)))?;
        match self.slots.remove(i).form {
            SlotForm::Functional(f) => Some(f),
            SlotForm::Form(_) => unreachable!("matched a functional"),
        }
    }
}

/// Binds `form` to slot `name` for `file` (a contact law's, with `contact`): a slot another
/// file provides already takes the sum of both forms (a problem's tractions add to the
/// material's `load`), when both are forms of the same time levels. A functional is one file's
/// (an energy summed from two laws would hide which law it measures), except between contact
/// laws: an obstacle's and the pairs' contact energies are together the run's.
pub(super) fn add_to_slot<'m>(
    slots: &mut Vec<Provided<'m>>,
    name: &str,
    form: SlotForm<'m>,
    file: &str,
    contact: bool,
) -> Result<(), CaseError> {
    let Some(i) = slots.iter().position(|p| p.name == name) else {
        slots.push(Provided { name: name.to_string(), form, file: file.to_string(), contact });
        return Ok(());
    };
    let earlier = slots.remove(i);
    let other = &earlier.file;
    let both_forms = matches!((&earlier.form, &form), (SlotForm::Form(_), SlotForm::Form(_)));
    let both_functionals = matches!((&earlier.form, &form), (SlotForm::Functional(_), SlotForm::Functional(_)));
    let contact_functionals = both_functionals && contact && earlier.contact;
    if !(both_forms || contact_functionals) {
        return Err(CaseError::Option(format!(
            "slot `{name}` is provided by both {other} and {file}: a functional is one file's (two would not say which law it measures); drop one of the files"
        )));
    }
    let fields = |f: &SlotForm| match f {
        SlotForm::Form(f) => f.fields(),
        SlotForm::Functional(f) => f.fields(),
    };
    let (a, b) = (fields(&earlier.form), fields(&form));
    if a != b {
        return Err(CaseError::Option(format!(
            "slot `{name}` is provided by {other} on {a} time level(s) and by {file} on {b}: forms added to one slot take the same levels"
        )));
    }
    let sum = match (earlier.form, form) {
        (SlotForm::Form(a), SlotForm::Form(b)) => SlotForm::Form(Box::new(Summed::new(vec![a, b]))),
        (SlotForm::Functional(a), SlotForm::Functional(b)) => {
            SlotForm::Functional(Box::new(SummedFunctional::new(vec![a, b])))
        }
        _ => unreachable!("both forms or both functionals"),
    };
    let file = if other == file { file.to_string() } else { format!("{other} + {file}") };
    slots.insert(i, Provided { name: name.to_string(), form: sum, file, contact: contact && earlier.contact });
    Ok(())
}
