//! A checked unit with its time schemes compiled: what the back ends (IR, Rust, the
//! interpreter) read. It is the checked [`Unit`] (params, coefs, forms, globals, sources)
//! plus the compiled schemes and the forms' IR, and derefs to the unit.

use std::ops::Deref;

use crate::check::Unit;
use crate::ir::DimIr;
use crate::scheme::SchemeIr;

pub struct Program {
    pub unit: Unit,
    /// Time schemes, compiled (their affine relations solved), in declaration order.
    pub schemes: Vec<SchemeIr>,
    /// The forms' IR for each dimension of `ir::DIMS`, in order. Built by the front end, which
    /// refuses what lowering finds (non-finite constants, expansion and degree limits).
    pub irs: Vec<DimIr>,
}

impl Deref for Program {
    type Target = Unit;

    fn deref(&self) -> &Unit {
        &self.unit
    }
}
