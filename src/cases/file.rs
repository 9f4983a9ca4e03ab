//! Case files: `signorini run case.toml` names a problem (`case = "bar"`, `case =
//! "my_problem.wf"`) and sets the options of `signorini run` as keys, the problem's params as
//! keys of their own (`ne = 40`), and the params of the scheme and form files in `[params]`
//! (`alpha = 0.1`, or per file: `[params.elasticity] rho = 2`), the only place they go. Unknown
//! keys, unknown params and out-of-range values are refused with the line of the key.

use std::path::{Path, PathBuf};

use clap::ValueEnum;
use serde::Deserialize;
use toml::Spanned;

use crate::driver::{self, Methods, Setting};
use crate::error::CaseError;
use crate::runtime::fem::mesh::CellSize;
use crate::simulation::MassChoice;

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
    mass: Option<Spanned<String>>,
    /// `diameter` or `getfem`.
    cell_size: Option<Spanned<String>>,
    dt: Option<Spanned<f64>>,
    t_end: Option<Spanned<f64>>,
    /// Problems: the start time (the problem's default otherwise).
    t_start: Option<Spanned<f64>>,
    /// Adaptive steps (`--adaptive`, `--dt-min`, `--dt-max`, `--event-dt`).
    adaptive: Option<Spanned<f64>>,
    dt_min: Option<Spanned<f64>>,
    dt_max: Option<Spanned<f64>>,
    event_dt: Option<Spanned<f64>>,
    out: Option<Spanned<String>>,
    /// A Gmsh file instead of the problem's mesh.
    mesh: Option<Spanned<String>>,
    /// Step cuts and the energy check (`--max-step-cuts`, `--energy-tolerance`).
    max_step_cuts: Option<Spanned<i64>>,
    energy_tolerance: Option<Spanned<f64>>,
    /// `--allow-unstable-dt`.
    allow_unstable_dt: Option<Spanned<bool>>,
    /// The linear solver (`--solver`) and PETSc's options (`--petsc-options`).
    solver: Option<Spanned<String>>,
    petsc_options: Option<Spanned<String>>,
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
}

/// The top-level keys of a case file that are params of its problem.
struct ProblemKeys {
    settings: Vec<Result<Setting, CaseError>>,
    /// The text without them.
    options: String,
    /// What the problem calls itself and its params, for the error at an unknown key.
    problem: String,
    names: Vec<String>,
}

/// The top-level keys of a case file that are params of its problem, as settings, and the text
/// with them blanked out (lines and offsets kept) for the options' parser. None when the text
/// does not parse or has no `case` string (the options' parser then says why); the problem's
/// own error, at the `case` line, when it does not load.
fn problem_params(text: &str, file: &str, base: &Path) -> Result<Option<ProblemKeys>, CaseError> {
    let (Ok(table), Ok(spans)) = (toml::from_str::<toml::Table>(text), toml::de::DeTable::parse(text)) else {
        return Ok(None);
    };
    let Some(case) = table.get("case").and_then(|c| c.as_str()) else { return Ok(None) };
    let pf = crate::problem::load(&name_or_path(case, base)).map_err(|e| match e {
        CaseError::Option(m) => {
            let at = spans.get_ref().iter().find(|(k, _)| k.get_ref() == "case").map_or(0, |(k, _)| k.span().start);
            let line = text[..at.min(text.len())].matches('\n').count() + 1;
            CaseError::CaseFile(format!("{file}:{line}: `case`: {m}"))
        }
        e => e,
    })?;
    let names: Vec<&str> = pf.problem().params.iter().map(|q| q.name.name.as_str()).collect();
    let mut blanked = text.as_bytes().to_vec();
    let mut settings = Vec::new();
    for (key, value) in spans.get_ref().iter() {
        let name: &str = key.get_ref();
        if !names.contains(&name) {
            continue;
        }
        let (start, end) = (key.span().start, value.span().end.min(text.len()));
        let line = text[..start].matches('\n').count() + 1;
        let origin = format!("{file}:{line}");
        let v = &table[name];
        settings.push(match v.as_float().or_else(|| v.as_integer().map(|i| i as f64)) {
            Some(value) => Ok(Setting { name: name.to_string(), value, origin }),
            None => {
                Err(CaseError::CaseFile(format!("{origin}: `{name}`: a param of problem `{}` is a number", pf.name())))
            }
        });
        for b in &mut blanked[start..end] {
            if *b != b'\n' {
                *b = b' ';
            }
        }
    }
    let Ok(options) = String::from_utf8(blanked) else { return Ok(None) };
    Ok(Some(ProblemKeys {
        settings,
        options,
        problem: pf.name().to_string(),
        names: names.iter().map(|n| n.to_string()).collect(),
    }))
}

/// Reads and checks a case file. Relative paths in it are relative to the file.
/// It names a problem of the library (`case = "sphere"`) or a problem file (`case = "ring.wf"`,
/// relative to the case file): the result is that problem's run.
pub fn read(path: &Path) -> Result<crate::problem::run::Options, CaseError> {
    use crate::runtime::input::{MAX_CASE_FILE_BYTES, read_bounded};
    let err = |e: String| CaseError::CaseFile(format!("{}: {e}", path.display()));
    let bytes = read_bounded(path, MAX_CASE_FILE_BYTES, "case file").map_err(|e| err(e.to_string()))?;
    let text = String::from_utf8(bytes).map_err(|_| err("not UTF-8 text".into()))?;
    parse(&text, path)
}

/// Checks the text of a case file read from `path` (for messages and relative paths).
pub fn parse(text: &str, path: &Path) -> Result<crate::problem::run::Options, CaseError> {
    let file = path.display().to_string();
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let keys = problem_params(text, &file, &base)?;
    let options = keys.as_ref().map_or(text, |k| k.options.as_str());
    let parsed: CaseFile = toml::from_str(options).map_err(|e| {
        let line = e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        let mut message = e.message().trim_end().to_string();
        if let Some(k) = keys.as_ref().filter(|_| message.starts_with("unknown field")) {
            let params = if k.names.is_empty() { "none".to_string() } else { k.names.join(", ") };
            message.push_str(&format!("; nor a param of problem `{}` (its params: {params})", k.problem));
        }
        CaseError::CaseFile(format!("{file}:{}: {message}", line.map_or("?".into(), |l| l.to_string())))
    })?;
    let problem_settings = keys.map(|k| k.settings).unwrap_or_default();
    let r = Reader { file: &file, text };
    let mass: MassChoice = r.choice(&parsed.mass, "mass", MassChoice::default())?;
    let methods = methods(&r, &parsed, &base)?;
    let cell_size = match &parsed.cell_size {
        None => CellSize::default(),
        Some(s) => CellSize::parse(s.get_ref()).map_err(|e| r.error(s, "cell_size", e))?,
    };
    let out = parsed.out.as_ref().map(|o| base.join(o.get_ref()));
    let problem = name_or_path(parsed.case.get_ref(), &base);
    // The problem must exist (its own errors are located in its file).
    crate::problem::load(&problem).map_err(|e| match e {
        CaseError::Option(m) => r.error(&parsed.case, "case", m),
        e => e,
    })?;
    let positive = |v: &Option<Spanned<f64>>, key: &str| -> Result<Option<f64>, CaseError> {
        v.as_ref().map(|_| r.number(v, key, |x| x > 0.0, "positive", 0.0)).transpose()
    };
    let mut methods = methods;
    for (i, s) in problem_settings.into_iter().enumerate() {
        methods.params.insert(i, s?);
    }
    let mut opts = crate::problem::run::Options::new(&problem);
    opts.chosen = crate::problem::run::Chosen {
        scheme: parsed.scheme.is_some(),
        contact: parsed.contact.is_some(),
        material: parsed.material.is_some(),
    };
    opts.methods = methods;
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
    opts.steps = crate::problem::run::StepOptions {
        adaptive: positive(&parsed.adaptive, "adaptive")?,
        dt_min: positive(&parsed.dt_min, "dt_min")?,
        dt_max: positive(&parsed.dt_max, "dt_max")?,
        event_dt: positive(&parsed.event_dt, "event_dt")?,
    };
    if let Some(s) = &parsed.solver {
        opts.newton.solver = crate::runtime::linalg::Solver::parse(s.get_ref()).map_err(|e| r.error(s, "solver", e))?;
    }
    opts.petsc_options = parsed.petsc_options.as_ref().map(|o| o.get_ref().clone());
    opts.out = out;
    Ok(opts)
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
fn methods(r: &Reader, parsed: &CaseFile, base: &Path) -> Result<Methods, CaseError> {
    let d = Methods::default();
    let mut methods = Methods {
        scheme: parsed.scheme.as_ref().map_or(d.scheme, |s| name_or_path(s.get_ref(), base)),
        contact: parsed.contact.as_ref().map_or(d.contact, |s| name_or_path(s.get_ref(), base)),
        material: parsed.material.as_ref().map_or(d.material, |s| name_or_path(s.get_ref(), base)),
        forms: parsed.forms.as_ref().map_or_else(Vec::new, |f| f.get_ref().iter().map(|p| base.join(p)).collect()),
        generated: Vec::new(),
        compiled: Vec::new(),
        params: Vec::new(),
        pairs: Vec::new(),
        guard: crate::guard::Guard {
            allow_unstable_dt: parsed.allow_unstable_dt.as_ref().map_or(d.guard.allow_unstable_dt, |b| *b.get_ref()),
            max_step_cuts: match &parsed.max_step_cuts {
                None => d.guard.max_step_cuts,
                Some(s) => crate::guard::step_cuts(*s.get_ref()).map_err(|e| r.error(s, "max_step_cuts", e))?,
            },
            energy_tolerance: r.number(
                &parsed.energy_tolerance,
                "energy_tolerance",
                |x| x >= 0.0,
                "0 (off) or positive",
                d.guard.energy_tolerance,
            )?,
        },
    };
    let at = |span: std::ops::Range<usize>| format!("{}:{}", r.file, r.line(span.start));
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
                    methods.params.push(Setting { name: format!("{name}.{p}"), value, origin: line });
                }
            }
            v => {
                let value = number(v).ok_or_else(|| bad(name))?;
                methods.params.push(Setting { name: name.clone(), value, origin });
            }
        }
    }
    // Resolve now, so that a bad name is reported at its key.
    driver::scheme(&methods).map_err(|e| match &parsed.scheme {
        Some(s) => r.error(s, "scheme", e),
        None => e,
    })?;
    driver::form_units(&methods).map_err(|e| match (&parsed.contact, &parsed.forms, &parsed.material) {
        (Some(s), _, _) if e.to_string().contains(s.get_ref().as_str()) => r.error(s, "contact", e),
        (_, Some(f), _) => r.error(f, "forms", e),
        (_, _, Some(m)) => r.error(m, "material", e),
        (Some(s), _, _) => r.error(s, "contact", e),
        _ => e,
    })?;
    Ok(methods)
}

/// Where a case file's outputs go when it names none.
pub fn default_out(path: &Path) -> PathBuf {
    PathBuf::from("results").join(path.file_stem().unwrap_or_default())
}
