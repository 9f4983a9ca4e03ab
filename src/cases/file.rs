//! Case files: `signorini run case.toml` with every option of `run bar` / `run disc` as keys.
//! Unknown keys, keys of the other case and out-of-range values are refused with the line of
//! the key.

use std::path::{Path, PathBuf};

use clap::ValueEnum;
use serde::Deserialize;
use toml::Spanned;

use super::CaseError;
use super::bar::{self, MassChoice, SchemeChoice};
use super::disc;
use super::static_block::ContactMethod;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
    case: Spanned<String>,
    scheme: Option<Spanned<String>>,
    alpha: Option<Spanned<f64>>,
    contact: Option<Spanned<String>>,
    theta: Option<Spanned<f64>>,
    gamma0: Option<Spanned<f64>>,
    mass: Option<Spanned<String>>,
    dt: Option<Spanned<f64>>,
    t_end: Option<Spanned<f64>>,
    out: Option<Spanned<String>>,
    /// bar only.
    ne: Option<Spanned<i64>>,
    /// disc only.
    mesh: Option<Spanned<String>>,
    h: Option<Spanned<f64>>,
}

/// A case read from a file.
pub enum Case {
    Bar(bar::Options),
    Disc(disc::Options),
}

struct Reader<'a> {
    file: &'a str,
    text: &'a str,
}

impl Reader<'_> {
    fn line(&self, offset: usize) -> usize {
        self.text[..offset.min(self.text.len())].matches('\n').count() + 1
    }

    fn error<T>(&self, value: &Spanned<T>, key: &str, reason: impl std::fmt::Display) -> CaseError {
        CaseError::CaseFile(format!("{}:{}: `{key}`: {reason}", self.file, self.line(value.span().start)))
    }

    fn number(
        &self,
        v: &Option<Spanned<f64>>,
        key: &str,
        ok: impl Fn(f64) -> bool,
        want: &str,
        default: f64,
    ) -> Result<f64, CaseError> {
        match v {
            None => Ok(default),
            Some(s) if ok(*s.get_ref()) && s.get_ref().is_finite() => Ok(*s.get_ref()),
            Some(s) => Err(self.error(s, key, format!("{} is not {want}", s.get_ref()))),
        }
    }

    fn choice<T: ValueEnum>(&self, v: &Option<Spanned<String>>, key: &str, default: T) -> Result<T, CaseError> {
        match v {
            None => Ok(default),
            Some(s) => T::from_str(s.get_ref(), true).map_err(|_| {
                let names: Vec<String> = T::value_variants()
                    .iter()
                    .filter_map(|x| x.to_possible_value())
                    .map(|p| p.get_name().to_string())
                    .collect();
                self.error(s, key, format!("`{}` is not one of {}", s.get_ref(), names.join(", ")))
            }),
        }
    }

    fn absent<T>(&self, v: &Option<Spanned<T>>, key: &str, case: &str) -> Result<(), CaseError> {
        match v {
            Some(s) => Err(self.error(s, key, format!("not an option of the {case} case"))),
            None => Ok(()),
        }
    }
}

/// Reads and checks a case file. Relative paths in it are relative to the file.
pub fn read(path: &Path) -> Result<Case, CaseError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| CaseError::CaseFile(format!("{file}: {e}")))?;
    let parsed: CaseFile = toml::from_str(&text).map_err(|e| {
        let line = e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        CaseError::CaseFile(format!("{file}:{}: {}", line.map_or("?".into(), |l| l.to_string()), e.message()))
    })?;
    let r = Reader { file: &file, text: &text };
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let scheme: SchemeChoice = r.choice(&parsed.scheme, "scheme", SchemeChoice::Newmark)?;
    let contact: ContactMethod = r.choice(&parsed.contact, "contact", ContactMethod::Nitsche)?;
    let mass: MassChoice = r.choice(&parsed.mass, "mass", MassChoice::Consistent)?;
    let theta = r.number(&parsed.theta, "theta", |x| (-1.0..=1.0).contains(&x), "in [-1, 1]", 1.0)?;
    let alpha = match &parsed.alpha {
        Some(a) if !scheme.is_hht() => {
            return Err(r.error(a, "alpha", format!("applies to the HHT schemes, not {}", scheme.name())));
        }
        a => a
            .as_ref()
            .map(|_| r.number(a, "alpha", |x| (0.0..=1.0 / 3.0).contains(&x), "in [0, 1/3]", 0.05))
            .transpose()?,
    };
    let out = parsed.out.as_ref().map(|o| base.join(o.get_ref()));
    match parsed.case.get_ref().as_str() {
        "bar" => {
            r.absent(&parsed.mesh, "mesh", "bar")?;
            r.absent(&parsed.h, "h", "bar")?;
            let d = bar::Options::default();
            let elements = match &parsed.ne {
                None => d.elements,
                Some(s) if (1..=100_000).contains(s.get_ref()) => *s.get_ref() as usize,
                Some(s) => return Err(r.error(s, "ne", format!("{} is not in 1..=100000", s.get_ref()))),
            };
            Ok(Case::Bar(bar::Options {
                scheme,
                alpha,
                contact,
                theta,
                gamma0: r.number(&parsed.gamma0, "gamma0", |x| x > 0.0, "positive", d.gamma0)?,
                elements,
                dt: r.number(&parsed.dt, "dt", |x| x > 0.0, "positive", d.dt)?,
                t_end: r.number(&parsed.t_end, "t_end", |x| x > 0.0, "positive", d.t_end)?,
                mass,
                out,
                ..d
            }))
        }
        "disc" => {
            r.absent(&parsed.ne, "ne", "disc")?;
            let d = disc::Options::default();
            Ok(Case::Disc(disc::Options {
                scheme,
                alpha,
                contact,
                theta,
                gamma0: r.number(&parsed.gamma0, "gamma0", |x| x > 0.0, "positive", d.gamma0)?,
                mass,
                mesh: parsed.mesh.as_ref().map(|m| base.join(m.get_ref())),
                h: r.number(&parsed.h, "h", |x| x > 0.05 && x <= 10.0, "in (0.05, 10]", d.h)?,
                dt: r.number(&parsed.dt, "dt", |x| x > 0.0, "positive", d.dt)?,
                t_end: r.number(&parsed.t_end, "t_end", |x| x > 0.0, "positive", d.t_end)?,
                out,
                ..d
            }))
        }
        other => Err(r.error(&parsed.case, "case", format!("`{other}` is not a case with a file form (bar, disc)"))),
    }
}

/// Where a case file's outputs go when it names none.
pub fn default_out(path: &Path) -> PathBuf {
    PathBuf::from("results").join(path.file_stem().unwrap_or_default())
}
