//! Case files: `signorini run case.toml` with every option of `run bar` / `run disc` (or of a
//! problem: `case = "sphere"`, `case = "my_problem.wf"`) as keys,
//! and the params of the scheme and form files in `[params]` (`alpha = 0.1`, or per file:
//! `[params.elasticity] rho = 2`). Unknown keys, unknown params, keys of the other case and
//! out-of-range values are refused with the line of the key.

use std::path::{Path, PathBuf};

use clap::ValueEnum;
use serde::Deserialize;
use toml::Spanned;

use super::CaseError;
use super::bar::{self, MassChoice};
use super::disc;
use crate::driver::{self, Setting, Setup};
use crate::runtime::mesh::CellSize;
use crate::simulation::MAX_STEP_CUTS;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseFile {
    case: Spanned<String>,
    scheme: Option<Spanned<String>>,
    contact: Option<Spanned<String>>,
    material: Option<Spanned<String>>,
    forms: Option<Spanned<Vec<String>>>,
    /// `name = value`, or `[params.OWNER]` tables of them.
    params: Option<std::collections::BTreeMap<String, Spanned<toml::Value>>>,
    /// Shorthands for `[params]` entries.
    alpha: Option<Spanned<f64>>,
    theta: Option<Spanned<f64>>,
    gamma0: Option<Spanned<f64>>,
    mass: Option<Spanned<String>>,
    /// `diameter` or `getfem`.
    cell_size: Option<Spanned<String>>,
    dt: Option<Spanned<f64>>,
    t_end: Option<Spanned<f64>>,
    /// Problems: the start time (the problem's default otherwise).
    t_start: Option<Spanned<f64>>,
    out: Option<Spanned<String>>,
    /// bar only.
    ne: Option<Spanned<i64>>,
    /// disc only.
    mesh: Option<Spanned<String>>,
    h: Option<Spanned<f64>>,
    /// Step cuts and the energy check (`--max-step-cuts`, `--max-energy-growth`).
    max_step_cuts: Option<Spanned<i64>>,
    max_energy_growth: Option<Spanned<f64>>,
}

/// A case read from a file.
pub enum Case {
    Bar(bar::Options),
    Disc(disc::Options),
    /// Any other problem of the library (`case = "sphere"`) or a problem file (`case =
    /// "ring.wf"`, relative to the case file).
    Problem(Box<crate::problem::run::Options>),
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
    let text = std::fs::read_to_string(path).map_err(|e| CaseError::CaseFile(format!("{}: {e}", path.display())))?;
    parse(&text, path)
}

/// Checks the text of a case file read from `path` (for messages and relative paths).
pub fn parse(text: &str, path: &Path) -> Result<Case, CaseError> {
    let file = path.display().to_string();
    let parsed: CaseFile = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        CaseError::CaseFile(format!("{file}:{}: {}", line.map_or("?".into(), |l| l.to_string()), e.message()))
    })?;
    let r = Reader { file: &file, text };
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mass: MassChoice = r.choice(&parsed.mass, "mass", MassChoice::Consistent)?;
    let setup = setup(&r, &parsed, &base)?;
    let cell_size = match &parsed.cell_size {
        None => CellSize::default(),
        Some(s) => CellSize::parse(s.get_ref()).map_err(|e| r.error(s, "cell_size", e))?,
    };
    let out = parsed.out.as_ref().map(|o| base.join(o.get_ref()));
    match parsed.case.get_ref().as_str() {
        "bar" => {
            r.absent(&parsed.mesh, "mesh", "bar")?;
            r.absent(&parsed.t_start, "t_start", "bar")?;
            r.absent(&parsed.h, "h", "bar")?;
            let d = bar::Options::default();
            let elements = match &parsed.ne {
                None => d.elements,
                Some(s) if (1..=100_000).contains(s.get_ref()) => *s.get_ref() as usize,
                Some(s) => return Err(r.error(s, "ne", format!("{} is not in 1..=100000", s.get_ref()))),
            };
            Ok(Case::Bar(bar::Options {
                setup,
                elements,
                dt: r.number(&parsed.dt, "dt", |x| x > 0.0, "positive", d.dt)?,
                t_end: r.number(&parsed.t_end, "t_end", |x| x > 0.0, "positive", d.t_end)?,
                mass,
                cell_size,
                out,
                ..d
            }))
        }
        "disc" => {
            r.absent(&parsed.ne, "ne", "disc")?;
            let d = disc::Options::default();
            Ok(Case::Disc(disc::Options {
                setup,
                mass,
                cell_size,
                mesh: parsed.mesh.as_ref().map(|m| base.join(m.get_ref())),
                h: r.number(&parsed.h, "h", |x| x > 0.05 && x <= 10.0, "in (0.05, 10]", d.h)?,
                dt: r.number(&parsed.dt, "dt", |x| x > 0.0, "positive", d.dt)?,
                t_end: r.number(&parsed.t_end, "t_end", |x| x > 0.0, "positive", d.t_end)?,
                out,
                ..d
            }))
        }
        other => {
            r.absent(&parsed.ne, "ne", "problem")?;
            let problem = name_or_path(other, &base);
            // The problem must exist (its own errors are located in its file).
            crate::problem::load(&problem).map_err(|e| match e {
                CaseError::Option(m) => r.error(&parsed.case, "case", m),
                e => e,
            })?;
            let positive = |v: &Option<Spanned<f64>>, key: &str| -> Result<Option<f64>, CaseError> {
                v.as_ref().map(|_| r.number(v, key, |x| x > 0.0, "positive", 0.0)).transpose()
            };
            let mut setup = setup;
            if let Some(h) = &parsed.h {
                let origin = format!("{}:{}", r.file, r.line(h.span().start));
                setup.params.insert(0, Setting { name: "h".into(), value: *h.get_ref(), origin });
            }
            let mut opts = crate::problem::run::Options::new(&problem);
            opts.chosen = crate::problem::run::Chosen {
                scheme: parsed.scheme.is_some(),
                contact: parsed.contact.is_some(),
                material: parsed.material.is_some(),
            };
            opts.setup = setup;
            opts.mass = mass;
            opts.cell_size = cell_size;
            opts.mesh = parsed.mesh.as_ref().map(|m| base.join(m.get_ref()));
            opts.dt = positive(&parsed.dt, "dt")?;
            opts.t_end = positive(&parsed.t_end, "t_end")?;
            opts.t_start = parsed
                .t_start
                .as_ref()
                .map(|_| r.number(&parsed.t_start, "t_start", |x| x >= 0.0, "0 or positive", 0.0))
                .transpose()?;
            opts.out = out;
            Ok(Case::Problem(Box::new(opts)))
        }
    }
}

/// A name of the library, or a path relative to the case file.
fn name_or_path(value: &str, base: &Path) -> String {
    if value.ends_with(".wf") || value.contains('/') {
        base.join(value).display().to_string()
    } else {
        value.to_string()
    }
}

/// The scheme, forms and params of a case file, checked against the library (errors at the
/// key's line).
fn setup(r: &Reader, parsed: &CaseFile, base: &Path) -> Result<Setup, CaseError> {
    let d = Setup::default();
    let mut setup = Setup {
        scheme: parsed.scheme.as_ref().map_or(d.scheme, |s| name_or_path(s.get_ref(), base)),
        contact: parsed.contact.as_ref().map_or(d.contact, |s| name_or_path(s.get_ref(), base)),
        material: parsed.material.as_ref().map_or(d.material, |s| name_or_path(s.get_ref(), base)),
        forms: parsed.forms.as_ref().map_or_else(Vec::new, |f| f.get_ref().iter().map(|p| base.join(p)).collect()),
        compiled: Vec::new(),
        params: Vec::new(),
        guard: crate::simulation::Guard {
            max_step_cuts: match &parsed.max_step_cuts {
                None => d.guard.max_step_cuts,
                Some(s) if (0..=MAX_STEP_CUTS as i64).contains(s.get_ref()) => *s.get_ref() as usize,
                Some(s) => {
                    return Err(r.error(s, "max_step_cuts", format!("{} is not in 0..={MAX_STEP_CUTS}", s.get_ref())));
                }
            },
            max_energy_growth: r.number(
                &parsed.max_energy_growth,
                "max_energy_growth",
                |x| x >= 0.0,
                "0 (off) or positive",
                d.guard.max_energy_growth,
            )?,
        },
    };
    let at = |span: std::ops::Range<usize>| format!("{}:{}", r.file, r.line(span.start));
    for (key, v) in [("alpha", &parsed.alpha), ("theta", &parsed.theta), ("gamma0", &parsed.gamma0)] {
        if let Some(v) = v {
            setup.params.push(Setting { name: key.into(), value: *v.get_ref(), origin: at(v.span()) });
        }
    }
    let number = |v: &toml::Value| v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
    for (name, entry) in parsed.params.iter().flatten() {
        let origin = at(entry.span());
        let bad = |what: &str| CaseError::CaseFile(format!("{origin}: `params.{what}`: expected a number"));
        match entry.get_ref() {
            toml::Value::Table(values) => {
                // Values inside a table carry no span of their own: find the key's line in it.
                for (p, v) in values {
                    let value = number(v).ok_or_else(|| bad(&format!("{name}.{p}")))?;
                    let span = entry.span();
                    let body = &r.text[span.start.min(r.text.len())..];
                    let line = body
                        .match_indices('\n')
                        .map(|(i, _)| i + 1)
                        .find(|&i| {
                            body[i..]
                                .trim_start()
                                .strip_prefix(p.as_str())
                                .is_some_and(|t| t.trim_start().starts_with('='))
                        })
                        .map_or(origin.clone(), |i| at(span.start + i..span.start + i));
                    setup.params.push(Setting { name: format!("{name}.{p}"), value, origin: line });
                }
            }
            v => {
                let value = number(v).ok_or_else(|| bad(name))?;
                setup.params.push(Setting { name: name.clone(), value, origin });
            }
        }
    }
    // Resolve now, so that a bad name is reported at its key.
    driver::scheme(&setup).map_err(|e| match &parsed.scheme {
        Some(s) => r.error(s, "scheme", e),
        None => e,
    })?;
    driver::form_units(&setup).map_err(|e| match (&parsed.contact, &parsed.forms, &parsed.material) {
        (Some(s), _, _) if e.to_string().contains(s.get_ref().as_str()) => r.error(s, "contact", e),
        (_, Some(f), _) => r.error(f, "forms", e),
        (_, _, Some(m)) => r.error(m, "material", e),
        (Some(s), _, _) => r.error(s, "contact", e),
        _ => e,
    })?;
    Ok(setup)
}

/// Where a case file's outputs go when it names none.
pub fn default_out(path: &Path) -> PathBuf {
    PathBuf::from("results").join(path.file_stem().unwrap_or_default())
}
