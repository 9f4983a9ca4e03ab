//! What the compiler produces and the runtime consumes: the description of a compiled `.wf`
//! file's params, coefs and slots, and of its schemes' stages. Generated code writes these as
//! constants; the interpreter builds the same values at run time; the runtime reads them
//! whichever way they came.

#![forbid(unsafe_code)]

pub mod params;
pub mod scheme;
pub mod slots;

pub use params::{CoefInfo, ParamError, ParamInfo, ParamRange, check_param};
pub use scheme::{Combination, InitialDesc, Level, SchemeDesc, StageDesc, TermDesc};
pub use slots::{SlotInfo, SlotUse};
