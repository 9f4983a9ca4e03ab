//! What the compiler produces and the runtime consumes: the description of a compiled `.wf`
//! file's params, coefs and slots, and of its schemes' stages. Generated code writes these as
//! constants, borrowing `'static` text and lists; the interpreter builds the same values at run
//! time, owning theirs; the runtime reads them whichever way they came.

#![forbid(unsafe_code)]

pub mod params;
pub mod scheme;
pub mod slots;

use std::borrow::Cow;

/// How generated constants write a descriptor's text and lists: `Borrowed("mass")`,
/// `Borrowed(&[...])`.
pub use std::borrow::Cow::Borrowed;

/// Text of a descriptor: borrowed from a constant, or owned.
pub type Text = Cow<'static, str>;

/// A list of a descriptor: borrowed from a constant, or owned.
pub type List<T> = Cow<'static, [T]>;

pub use params::{CoefInfo, ParamError, ParamInfo, ParamRange, check_param};
pub use scheme::{Combination, InitialDesc, Level, SchemeDesc, StageDesc, TermDesc};
pub use slots::{SlotInfo, SlotUse};
