//! The form library of `forms/`, compiled into kernels for the built-in cases.

crate::forms!(pub mod nitsche = "forms/contact_nitsche.wf");
crate::forms!(pub mod penalty = "forms/contact_penalty.wf");
