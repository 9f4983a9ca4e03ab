//! Params and coefs as a compiled file declares them: names, defaults, ranges, docs and where
//! they are declared; the range check every way of setting a param goes through.

use std::fmt;

/// A param of a form file or a scheme.
#[derive(Clone, Copy, Debug)]
pub struct ParamInfo {
    pub name: &'static str,
    pub default: f64,
    pub range: ParamRange,
    /// The comment on the declaration's line (or the line above), if any.
    pub doc: &'static str,
    /// `file.wf:line`.
    pub declared: &'static str,
    /// The default and range as written in the file (`0.05 in [0, 1/3]`).
    pub written: &'static str,
    /// The file stem or scheme that declares it: `owner.name` is its qualified name.
    pub owner: &'static str,
}

/// A `coef` (case data) of a form file.
#[derive(Clone, Copy, Debug)]
pub struct CoefInfo {
    pub name: &'static str,
    /// 0 scalar, 1 vector, 2 tensor.
    pub rank: u32,
    pub doc: &'static str,
    pub declared: &'static str,
}

/// A parameter value refused by a generated `Params`.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamError {
    Unknown { name: String, known: &'static [&'static str] },
    OutOfRange { name: &'static str, value: f64, range: String },
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

/// The declared range of a parameter (unbounded sides are infinite and open).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamRange {
    pub name: &'static str,
    pub lo: f64,
    pub lo_closed: bool,
    pub hi: f64,
    pub hi_closed: bool,
}

impl ParamRange {
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

/// Range check used by generated `Params::set`: the value if it lies in the range.
pub fn check_param(range: &ParamRange, value: f64) -> Result<f64, ParamError> {
    if range.contains(value) {
        Ok(value)
    } else {
        Err(ParamError::OutOfRange { name: range.name, value, range: range.to_string() })
    }
}
