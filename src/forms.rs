//! The form library of `forms/`, compiled into kernels for the built-in cases.

crate::forms!(pub mod nitsche = "forms/contact_nitsche.wf");
crate::forms!(pub mod penalty = "forms/contact_penalty.wf");

/// The time schemes of `forms/schemes/`, one module each.
pub mod schemes {
    crate::forms!(pub mod newmark = "forms/schemes/newmark.wf");
    crate::forms!(pub mod hht = "forms/schemes/hht.wf");
    crate::forms!(pub mod hht_imex = "forms/schemes/hht_imex.wf");
    crate::forms!(pub mod hht_unweighted = "forms/schemes/hht_unweighted.wf");
    crate::forms!(pub mod midpoint = "forms/schemes/midpoint.wf");
    crate::forms!(pub mod trbdf2 = "forms/schemes/trbdf2.wf");
    crate::forms!(pub mod hybrid = "forms/schemes/hybrid.wf");
}
