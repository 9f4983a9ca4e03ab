//! A checked unit with its time schemes compiled: what the back ends (IR, Rust, the
//! interpreter) read. It is the checked [`Unit`] (params, coefs, forms, globals, sources)
//! plus the compiled schemes, and derefs to the unit.

use std::ops::Deref;

use crate::check::Unit;
use crate::scheme::SchemeIr;

pub struct Program {
    pub unit: Unit,
    /// Time schemes, compiled (their affine relations solved), in declaration order.
    pub schemes: Vec<SchemeIr>,
}

impl Deref for Program {
    type Target = Unit;

    fn deref(&self) -> &Unit {
        &self.unit
    }
}
