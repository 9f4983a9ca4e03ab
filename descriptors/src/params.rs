//! Params and coefs as a compiled file declares them: names, defaults, ranges, docs and where
//! they are declared; the range check every way of setting a param goes through.

use std::fmt;

use crate::Text;

/// A param of a form file or a scheme.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamInfo {
    pub name: Text,
    pub default: f64,
    pub range: ParamRange,
    /// The comment on the declaration's line (or the line above), if any.
    pub doc: Text,
    /// `file.wf:line`.
    pub declared: Text,
    /// The default and range as written in the file (`0.05 in [0, 1/3]`).
    pub written: Text,
    /// The file stem or scheme that declares it: `owner.name` is its qualified name.
    pub owner: Text,
}

/// A `coef` (case data) of a form file.
#[derive(Clone, Debug, PartialEq)]
pub struct CoefInfo {
    pub name: Text,
    /// 0 scalar, 1 vector, 2 tensor.
    pub rank: u32,
    pub doc: Text,
    pub declared: Text,
}

/// A parameter value refused: by a generated `Params`, or by a scheme or form file loaded at
/// run time.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamError {
    Unknown { name: String, known: Vec<String> },
    OutOfRange { name: String, value: f64, range: String },
}

impl ParamError {
    /// `name` is none of `known`.
    pub fn unknown(name: &str, known: &[&str]) -> ParamError {
        ParamError::Unknown { name: name.to_string(), known: known.iter().map(|k| k.to_string()).collect() }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamError::Unknown { name, known } => {
                write!(f, "unknown parameter `{name}` (known: {})", known.join(", "))
            }
            ParamError::OutOfRange { name, value, range } => {
                write!(f, "parameter `{name}` = {value} is outside its range {range}")
            }
        }
    }
}

impl std::error::Error for ParamError {}

/// The declared range of a parameter (unbounded sides are infinite and open). The compiler's
/// checks, generated `Params` and the interpreter all decide with [`ParamRange::contains`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamRange {
    pub lo: f64,
    pub lo_closed: bool,
    pub hi: f64,
    pub hi_closed: bool,
}

impl ParamRange {
    /// The range of a param declared without one: every finite value.
    pub const UNBOUNDED: ParamRange =
        ParamRange { lo: f64::NEG_INFINITY, lo_closed: false, hi: f64::INFINITY, hi_closed: false };

    /// Whether `v` is finite and in the range (a closed infinite bound admits no infinity).
    pub fn contains(&self, v: f64) -> bool {
        let above = if self.lo_closed { v >= self.lo } else { v > self.lo };
        let below = if self.hi_closed { v <= self.hi } else { v < self.hi };
        v.is_finite() && above && below
    }
}

impl fmt::Display for ParamRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let b = |v: f64| {
            if v.is_infinite() { if v > 0.0 { "inf".to_string() } else { "-inf".to_string() } } else { format!("{v}") }
        };
        write!(
            f,
            "{}{}, {}{}",
            if self.lo_closed { "[" } else { "(" },
            b(self.lo),
            b(self.hi),
            if self.hi_closed { "]" } else { ")" }
        )
    }
}

/// The range check of param `name` (generated `Params::set`, the interpreter): the value if it
/// lies in the range.
pub fn check_param(name: &str, range: &ParamRange, value: f64) -> Result<f64, ParamError> {
    if range.contains(value) {
        Ok(value)
    } else {
        Err(ParamError::OutOfRange { name: name.to_string(), value, range: range.to_string() })
    }
}
