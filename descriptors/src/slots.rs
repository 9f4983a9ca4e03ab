//! Slots: the forms and functionals a file provides under their names, and those a scheme
//! applies.

use crate::Text;

/// A form or functional a file provides, under its name.
#[derive(Clone, Debug, PartialEq)]
pub struct SlotInfo {
    pub name: Text,
    /// Field arguments (time levels); 0 for a load.
    pub fields: usize,
    /// A functional (no test function): a value, not a residual.
    pub functional: bool,
    pub doc: Text,
    pub declared: Text,
}

/// A slot a scheme applies.
#[derive(Clone, Debug, PartialEq)]
pub struct SlotUse {
    pub name: Text,
    /// Time levels it is applied to; 0 for a load.
    pub fields: usize,
    /// `file.wf:line:col` of its name in the `uses` line.
    pub declared: Text,
}
