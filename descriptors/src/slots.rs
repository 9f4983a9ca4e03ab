//! Slots: the forms and functionals a file provides under their names, and those a scheme
//! applies.

/// A form or functional a file provides, under its name.
#[derive(Clone, Copy, Debug)]
pub struct SlotInfo {
    pub name: &'static str,
    /// Field arguments (time levels); 0 for a load.
    pub fields: usize,
    /// A functional (no test function): a value, not a residual.
    pub functional: bool,
    pub doc: &'static str,
    pub declared: &'static str,
}

/// A slot a scheme applies.
#[derive(Clone, Copy, Debug)]
pub struct SlotUse {
    pub name: &'static str,
    /// Time levels it is applied to; 0 for a load.
    pub fields: usize,
    /// `file.wf:line:col` of its name in the `uses` line.
    pub declared: &'static str,
}
