//! The bound forms of a run, by slot: what the form files in use provide once bound to a mesh.

use crate::error::CaseError;
use crate::runtime::fem::bound::{BoundForm, BoundFunctional};
use crate::runtime::library::SlotForm;

/// The bound forms of a run, taken by slot name (and the file that provides each).
pub struct Instance<'m> {
    pub(super) slots: Vec<(String, SlotForm<'m>, String)>,
}

impl<'m> Instance<'m> {
    /// The instances of one set of files on each of several bodies, each slot summed over them
    /// (every body's instance has the same slots, in the same order).
    pub(super) fn over_bodies(each: Vec<Instance<'m>>) -> Instance<'m> {
        let mut slots: Vec<(String, Vec<SlotForm<'m>>, String)> = Vec::new();
        for instance in each {
            for (k, (name, form, file)) in instance.slots.into_iter().enumerate() {
                match slots.get_mut(k) {
                    Some((_, parts, _)) => parts.push(form),
                    None => slots.push((name, vec![form], file)),
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
            use crate::runtime::fem::summed::{Summed, SummedFunctional};
            match forms.is_empty() {
                false => SlotForm::Form(Box::new(Summed::over_bodies(forms))),
                true => SlotForm::Functional(Box::new(SummedFunctional::over_bodies(functionals))),
            }
        };
        Instance { slots: slots.into_iter().map(|(name, parts, file)| (name, summed(parts), file)).collect() }
    }

    /// Takes the form of a slot (a functional or a missing slot: `None`).
    pub fn take_form(&mut self, name: &str) -> Option<Box<dyn BoundForm + 'm>> {
        let i = self.slots.iter().position(|(n, f, _)| *n == name && matches!(f, SlotForm::Form(_)))?;
        match self.slots.remove(i).1 {
            SlotForm::Form(f) => Some(f),
            SlotForm::Functional(_) => unreachable!("matched a form"),
        }
    }

    /// Whether a file in use provides the functional `name` (and it is not taken yet).
    pub fn provides_functional(&self, name: &str) -> bool {
        self.slots.iter().any(|(n, f, _)| n == name && matches!(f, SlotForm::Functional(_)))
    }

    /// Takes the functional of a slot.
    pub fn take_functional(&mut self, name: &str) -> Option<Box<dyn BoundFunctional + 'm>> {
        let i = self.slots.iter().position(|(n, f, _)| *n == name && matches!(f, SlotForm::Functional(_)))?;
        match self.slots.remove(i).1 {
            SlotForm::Functional(f) => Some(f),
            SlotForm::Form(_) => unreachable!("matched a functional"),
        }
    }
}

/// Binds `form` to slot `name` for `file`: a slot another file provides already takes the sum
/// of both forms (a problem's tractions add to the material's `load`), when both are forms of
/// the same time levels; a functional is one file's (an energy summed from two laws would
/// hide which law it measures).
pub(super) fn add_to_slot<'m>(
    slots: &mut Vec<(String, SlotForm<'m>, String)>,
    name: &str,
    form: SlotForm<'m>,
    file: &str,
) -> Result<(), CaseError> {
    let Some(i) = slots.iter().position(|(n, _, _)| n == name) else {
        slots.push((name.to_string(), form, file.to_string()));
        return Ok(());
    };
    let (_, earlier, other) = slots.remove(i);
    let (SlotForm::Form(a), SlotForm::Form(b)) = (earlier, form) else {
        return Err(CaseError::Option(format!(
            "slot `{name}` is provided by both {other} and {file}: a functional is one file's (two would not say which law it measures); drop one of the files"
        )));
    };
    if a.fields() != b.fields() {
        return Err(CaseError::Option(format!(
            "slot `{name}` is provided by {other} on {} time level(s) and by {file} on {}: forms added to one slot take the same levels",
            a.fields(),
            b.fields()
        )));
    }
    let sum = crate::runtime::fem::summed::Summed::new(vec![a, b]);
    slots.insert(i, (name.to_string(), SlotForm::Form(Box::new(sum)), format!("{other} + {file}")));
    Ok(())
}
