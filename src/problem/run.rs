//! The one loop every problem runs through: bind the problem (mesh, regions, coefs) and the
//! files in use (scheme, laws, params), initialize, step with cuts and the energy watch, measure
//! every row, checkpoint, then write series.csv, stages.csv, summary.json, the figure and the
//! VTU collection. Nothing in it names a problem.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::ProblemFile;
use super::expr::Exprs;
use super::observe::{Observer, State, SummaryKeys};
use crate::checkpoint::Control;
use crate::driver::{Active, ParamValue, Setup};
use crate::error::CaseError;
use crate::runtime::fem::assembly::{Assembler, Quadrature};
use crate::runtime::fem::mesh::CellSize;
use crate::runtime::library::Binding;
use crate::runtime::nonlinear::newton::NewtonOptions;
use crate::runtime::nonlinear::statics::Constraints;
use crate::simulation::{MassChoice, Problem, Simulation, Snapshots};

/// How to run a problem: the command line's or a case file's choices over the problem's.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// A library problem by name, or a problem file.
    pub problem: String,
    /// Scheme, contact law, extra forms, params (the problem's params among them).
    pub setup: Setup,
    pub mass: MassChoice,
    pub cell_size: CellSize,
    /// A Gmsh file instead of the problem's mesh.
    pub mesh: Option<PathBuf>,
    /// Run settings over the problem's `run` line.
    pub dt: Option<f64>,
    pub t_start: Option<f64>,
    pub t_end: Option<f64>,
    pub newton: NewtonOptions,
    pub out: Option<PathBuf>,
    pub vtu_every: usize,
    pub progress: bool,
    pub checkpoint_every: usize,
    pub resume: bool,
    /// The roles the user chose explicitly (`--scheme`, ...): the problem's `bind` lines give
    /// the others.
    pub chosen: Chosen,
}

/// Which of the setup's files the user chose; a problem's `bind` replaces the library's
/// defaults only.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Chosen {
    pub scheme: bool,
    pub contact: bool,
    pub material: bool,
}

impl Chosen {
    /// Every role chosen: the setup is taken as it is (programs that build their own).
    pub fn all() -> Chosen {
        Chosen { scheme: true, contact: true, material: true }
    }
}

impl Options {
    pub fn new(problem: &str) -> Options {
        Options {
            problem: problem.to_string(),
            setup: Setup::default(),
            mass: MassChoice::Consistent,
            cell_size: CellSize::Diameter,
            mesh: None,
            dt: None,
            t_start: None,
            t_end: None,
            newton: NewtonOptions::default(),
            out: None,
            vtu_every: 0,
            progress: false,
            checkpoint_every: 0,
            resume: false,
            chosen: Chosen::default(),
        }
    }
}

/// A finished run: its summary and rows (every column, shown or not).
pub struct Run {
    /// summary.json's keys in order: the shared ones, with the problem's own after `steps`.
    pub summary: Summary,
    /// Every column's name, in row order.
    pub columns: Vec<String>,
    /// (time, values) per row.
    pub rows: Vec<(f64, Vec<f64>)>,
    /// The `contact` slot's switch at each of its quadrature points, per row (the active set).
    pub switches: Vec<Vec<bool>>,
    /// Multi-stage schemes: (stage name, time, values) at every intermediate stage.
    pub stages: Vec<(String, f64, Vec<f64>)>,
}

impl Run {
    /// Where each named column is in a row's values (typed views of a problem's rows).
    pub fn indices<S: AsRef<str>>(&self, names: &[S], problem: &str) -> Result<Vec<usize>, CaseError> {
        names
            .iter()
            .map(|n| {
                let n = n.as_ref();
                self.columns
                    .iter()
                    .position(|c| c == n)
                    .ok_or_else(|| CaseError::Option(format!("the {problem} problem file has no column `{n}`")))
            })
            .collect()
    }

    /// A column's values over the rows.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let i = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r.1[i]).collect())
    }
}

/// The run's settings: the problem's `run` line under the options.
struct Settings {
    dt: f64,
    t_start: f64,
    t_end: f64,
}

/// Binds a problem with the library's defaults without running it: its params, the files in use
/// and their coefs, the mesh with its regions, the coefs' and initial fields' expressions in the
/// problem's dimension (`signorini check` on a problem file).
pub fn check(problem: &str) -> Result<(), CaseError> {
    let opts = Options::new(problem);
    bound(&opts, |pf, _, ex, _| {
        let p = pf.problem();
        reference(pf, ex.dim())?;
        super::bind::settings(pf, ex, &p.run)?;
        super::bind::settings(pf, ex, &p.quadrature)?;
        let (mesh, _) = super::bind::mesh(pf, ex, None, CellSize::Diameter)?;
        super::bind::coefs(pf, ex)?;
        super::bind::coef_vals(pf, ex)?;
        super::bind::initial(pf, ex, &mesh, "u", 0.0)?;
        super::bind::initial(pf, ex, &mesh, "v", 0.0)?;
        Ok(())
    })
}

pub fn run(opts: &Options) -> Result<Run, CaseError> {
    bound(opts, |pf, params, ex, active| {
        if pf.problem().run_static.is_some() {
            if opts.dt.is_some() || opts.t_end.is_some() || opts.t_start.is_some() {
                return Err(CaseError::Option(format!(
                    "{} is static (`run static`): it takes no --dt, --t-end or --t-start",
                    pf.file
                )));
            }
            let settings = Settings { dt: f64::NAN, t_start: 0.0, t_end: 0.0 };
            return simulate(opts, pf, params, ex, active, &settings);
        }
        let given = super::bind::settings(pf, ex, &pf.problem().run)?;
        let setting = |name: &str, over: Option<f64>, default: f64| {
            over.or_else(|| given.iter().find(|(n, _)| n == name).map(|(_, v)| *v)).unwrap_or(default)
        };
        let settings = Settings {
            dt: setting("dt", opts.dt, f64::NAN),
            t_start: setting("t_start", opts.t_start, 0.0),
            t_end: setting("t_end", opts.t_end, f64::NAN),
        };
        let positive = |x: f64| x > 0.0 && x.is_finite();
        if !positive(settings.dt) || !positive(settings.t_end) || settings.t_end / settings.dt > 1e7 {
            return Err(CaseError::Option(
                "--dt and --t-end (or the problem's `run dt = ..., t_end = ...`) must be positive, with at most 10⁷ steps"
                    .into(),
            ));
        }
        if !(settings.t_start >= 0.0 && settings.t_start < settings.t_end) {
            return Err(CaseError::Option(format!("--t-start must be in [0, t_end), not {}", settings.t_start)));
        }
        simulate(opts, pf, params, ex, active, &settings)
    })
}

/// Loads the problem, resolves its params and the files in use (the problem's `set` values as
/// the case's overrides, the user's settings over them), checks what the driver needs of it,
/// and hands the bound pieces to `f`.
fn bound<R>(
    opts: &Options,
    f: impl FnOnce(&ProblemFile, &[super::ProblemParam], &mut Exprs, &Active) -> Result<R, CaseError>,
) -> Result<R, CaseError> {
    let pf = super::load(&opts.problem)?;
    let (params, rest) = super::params(&pf, &opts.setup.params)?;
    let mut setup = Setup { params: rest, ..opts.setup.clone() };
    bind_files(&pf, &mut setup, opts.chosen);
    let values: Vec<(String, f64)> = params.iter().map(|p| (p.name.clone(), p.value)).collect();
    let d = super::bind::dimension(&pf, opts.mesh.as_deref(), &values)?;
    let p = pf.problem();
    let mut ex = Exprs::new(&pf.program.unit, d, &values, &p.lets).map_err(|e| pf.render(*e))?;
    let mut sets = Vec::new();
    for s in &p.sets {
        sets.push((s.name.name.clone(), ex.scalar(&s.value).map_err(|e| pf.render(*e))?));
    }
    let overrides: Vec<(&str, f64)> = sets.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    let active = Active::resolve(&setup, &overrides)?;
    unset_coefs(&pf, &active)?;
    f(&pf, &params, &mut ex, &active)
}

/// The problem's `bind` lines, for the roles the user did not choose; a path is relative to the
/// problem file.
fn bind_files(pf: &ProblemFile, setup: &mut Setup, chosen: Chosen) {
    for b in &pf.problem().binds {
        let target = if b.is_path { pf.dir.join(&b.target).display().to_string() } else { b.target.clone() };
        match b.role.name.as_str() {
            "scheme" if !chosen.scheme => setup.scheme = target,
            "contact" if !chosen.contact => setup.contact = target,
            "material" if !chosen.material => setup.material = target,
            "forms" => {
                let path = std::path::PathBuf::from(target);
                if !setup.forms.contains(&path) {
                    setup.forms.push(path);
                }
            }
            _ => {}
        }
    }
}

/// The problem's reference bound to this run, after it checked the run is one it describes.
fn bound_reference(
    pf: &ProblemFile,
    ex: &mut Exprs,
    active: &Active,
    mesh: &crate::runtime::fem::mesh::Mesh,
    contact: &[crate::runtime::fem::mesh::Facet],
    t_start: f64,
) -> Result<Option<crate::references::Bound>, CaseError> {
    let Some(r) = reference(pf, mesh.dim())? else { return Ok(None) };
    let param = |name: &str| active.forms.params.get(name);
    let args = reference_args(pf, ex, r)?;
    let facts = crate::references::RunFacts { mesh, param: &param, t_start, args: &args, contact };
    let bound = r.bind(&facts).map_err(|why| {
        let at = pf.problem().reference.as_ref().map_or(pf.problem().name.span, |n| n.span);
        pf.render(
            crate::compiler::Diagnostic::error(
                "E0101",
                format!("reference `{}` does not describe this run", r.name()),
                at,
                "named here",
            )
            .with_note(why)
            .with_note(format!("{}: {}", r.name(), r.doc())),
        )
    })?;
    Ok(Some((r, bound)))
}

/// The problem's reference, if it names one, for a problem of dimension `d`.
fn reference(pf: &ProblemFile, d: usize) -> Result<Option<&'static dyn crate::references::Reference>, CaseError> {
    use crate::compiler::Diagnostic;
    let Some(name) = &pf.problem().reference else { return Ok(None) };
    let names = crate::references::ALL.iter().map(|r| r.name());
    let r = crate::references::find(&name.name)
        .ok_or_else(|| pf.render(crate::compiler::check::problem::unknown_among(name, names, "reference")))?;
    if !r.dims().contains(&d) {
        let dims: Vec<String> = r.dims().iter().map(|d| format!("{d}D")).collect();
        return Err(pf.render(
            Diagnostic::error(
                "E0302",
                "wrong dimension",
                name.span,
                format!("reference `{}` is {}, the problem {d}D", r.name(), dims.join(" or ")),
            )
            .with_note(format!("{}: {}", r.name(), r.doc())),
        ));
    }
    Ok(Some(r))
}

/// The problem's arguments to its reference, evaluated; a name the reference does not take is
/// an error with its list.
fn reference_args(
    pf: &ProblemFile,
    ex: &mut Exprs,
    r: &dyn crate::references::Reference,
) -> Result<Vec<(String, f64)>, CaseError> {
    let known = r.args();
    let mut out = Vec::new();
    for a in &pf.problem().reference_args {
        if !known.iter().any(|(n, _)| *n == a.name.name) {
            return Err(pf.render(crate::compiler::check::problem::unknown_among(
                &a.name,
                known.iter().map(|(n, _)| *n),
                "reference argument",
            )));
        }
        out.push((a.name.name.clone(), ex.scalar(&a.value).map_err(|e| pf.render(*e))?));
    }
    Ok(out)
}

/// Every coef the files in use read must be set by the problem (a `coef` line, or an
/// obstacle's `g` and `nc`): a located error before anything runs. A coef the problem sets that
/// no file reads is a warning (a misspelt name, or a file left out).
fn unset_coefs(pf: &ProblemFile, active: &Active) -> Result<(), CaseError> {
    use crate::compiler::Diagnostic;
    let p = pf.problem();
    let read: Vec<String> = active.forms.units.iter().flat_map(|u| u.coefs()).map(|(n, _)| n).collect();
    for c in &p.coefs {
        if !read.contains(&c.name.name) {
            let files: Vec<&str> = active.forms.units.iter().map(|u| u.file()).collect();
            let w = crate::compiler::check::problem::unread_coef(&c.name, &files);
            eprintln!("{}", crate::compiler::render_all(&[w], &pf.program.unit.sources).trim_end());
        }
    }
    let mut set: Vec<&str> = p.coefs.iter().map(|c| c.name.name.as_str()).collect();
    if !p.obstacles.is_empty() {
        set.extend(["g", "nc"]);
    }
    let free = super::bind::contact_free(pf);
    for (i, unit) in active.forms.units.iter().enumerate() {
        if free && i == active.forms.contact {
            continue; // integrates over no facet: its coefs are zero
        }
        for (c, _) in unit.coefs() {
            if !set.contains(&c.as_str()) {
                let mut d = Diagnostic::error(
                    "E0101",
                    format!("problem `{}` does not set coef `{c}`, which {} reads", pf.name(), unit.file()),
                    p.name.span,
                    "no `coef` line for it",
                )
                .with_help(format!("add `coef {c} = EXPR` (an expression of x and t) to the problem"));
                if let Some(close) = crate::compiler::check::suggest_name(&c, set.iter().copied()) {
                    d = d.with_note(format!("the problem sets `{close}`: a misspelling?"));
                }
                return Err(pf.render(d));
            }
        }
    }
    Ok(())
}

/// Each coef the problem sets has the components the files in use read it with.
fn coef_shapes(
    pf: &ProblemFile,
    active: &Active,
    coefs: &[(String, super::expr::PointFn)],
    d: usize,
) -> Result<(), CaseError> {
    use crate::compiler::Diagnostic;
    for unit in &active.forms.units {
        for (name, rank) in unit.coefs() {
            let Some((_, f)) = coefs.iter().find(|(n, _)| *n == name) else { continue };
            let need = d.pow(rank);
            if f.len() != need {
                let at = pf
                    .problem()
                    .coefs
                    .iter()
                    .find(|c| c.name.name == name)
                    .map_or(pf.problem().name.span, |c| c.value.span);
                let shape = ["a scalar", "a vector", "a tensor"][rank.min(2) as usize];
                return Err(pf.render(Diagnostic::error(
                    "E0301",
                    "shape mismatch",
                    at,
                    format!("{} reads `{name}` as {shape} ({need} components in {d}D), not {}", unit.file(), f.len()),
                )));
            }
        }
    }
    Ok(())
}

/// The problem's Dirichlet conditions: the listed components of every node of each region
/// held, by elimination. Held at zero, they are the constraints alone; held at other values, or
/// at values that move with `t`, they are also the stepper's prescribed displacements (each
/// stage holds its displacement quantity at the values of its time).
fn dirichlet(
    pf: &ProblemFile,
    ex: &mut Exprs,
    mesh: &crate::runtime::fem::mesh::Mesh,
) -> Result<(Constraints, Option<Held>), CaseError> {
    use crate::compiler::Diagnostic;
    use crate::compiler::syntax::ast::HeldAt;
    let d = mesh.dim();
    let mut c = Constraints::none(mesh.num_nodes() * d);
    let mut held = Held { dofs: Vec::new(), at: Vec::new(), values: Vec::new() };
    for dc in &pf.problem().dirichlet {
        let components: Vec<usize> = match &dc.component {
            Some(k) => {
                let k = crate::compiler::check::const_value(k).unwrap_or(0.0) as usize;
                if k >= d {
                    return Err(pf.render(Diagnostic::error(
                        "E0302",
                        "wrong dimension",
                        dc.span,
                        format!("component {k} in a {d}D problem"),
                    )));
                }
                vec![k]
            }
            None => (0..d).collect(),
        };
        let value = ex.lower(&dc.value, &[]).map_err(|e| pf.render(*e))?;
        let f = ex.function(&value, &dc.value).map_err(|e| pf.render(*e))?;
        let zero = f.constant().is_some_and(|v| v.iter().all(|x| *x == 0.0));
        let nodes = match &dc.on {
            HeldAt::Region(r) => mesh.region_nodes(mesh.region(&r.name)?),
            HeldAt::Nearest { point, .. } => {
                let p = ex.vector(point).map_err(|e| pf.render(*e))?;
                if p.len() != d {
                    return Err(pf.render(Diagnostic::error(
                        "E0302",
                        "wrong dimension",
                        point.span,
                        format!("a point of {} components in a {d}D problem", p.len()),
                    )));
                }
                vec![nearest_node(mesh, &p) as u32]
            }
        };
        if !zero {
            held.values.push(f);
        }
        for node in nodes {
            for (j, &k) in components.iter().enumerate() {
                let dof = node as usize * d + k;
                c.fix(dof);
                // A later condition on the same dof replaces an earlier one.
                if let Some(i) = held.dofs.iter().position(|&x| x == dof) {
                    held.dofs.remove(i);
                    held.at.remove(i);
                }
                if !zero {
                    let comp = if dc.component.is_some() { 0 } else { j };
                    held.dofs.push(dof);
                    held.at.push((node as usize, held.values.len() - 1, comp));
                }
            }
        }
    }
    let held = (!held.dofs.is_empty()).then_some(held);
    Ok((c, held))
}

/// The mesh node nearest to `target` (the first of several as near).
fn nearest_node(mesh: &crate::runtime::fem::mesh::Mesh, target: &[f64]) -> usize {
    let dist = |i: usize| -> f64 { mesh.node(i).iter().zip(target).map(|(x, y)| (x - y).powi(2)).sum() };
    (0..mesh.num_nodes()).min_by(|&a, &b| dist(a).total_cmp(&dist(b))).unwrap_or(0)
}

/// Held displacements at nonzero or moving values: per dof, its node, its condition's values
/// and the component of them.
#[derive(Clone)]
struct Held {
    dofs: Vec<usize>,
    at: Vec<(usize, usize, usize)>,
    values: Vec<super::expr::PointFn>,
}

impl Held {
    /// The held values at time `t`, in the order of `dofs`.
    fn eval(&self, nodes: &[Vec<f64>], t: f64, out: &mut [f64]) {
        let mut scratch = Vec::new();
        let mut v = Vec::new();
        for (o, &(node, cond, comp)) in out.iter_mut().zip(&self.at) {
            let f = &self.values[cond];
            v.resize(f.len(), 0.0);
            f.eval(&super::expr::At { x: &nodes[node], t, ..Default::default() }, &mut scratch, &mut v);
            *o = v[comp];
        }
    }

    /// For the stepper: the values at a time.
    fn prescribed(&self, mesh: &crate::runtime::fem::mesh::Mesh) -> crate::runtime::time::stepper::Prescribed {
        let nodes: Vec<Vec<f64>> = (0..mesh.num_nodes()).map(|i| mesh.node(i).to_vec()).collect();
        let me = self.clone();
        crate::runtime::time::stepper::Prescribed {
            dofs: self.dofs.clone(),
            values: Box::new(move |t, out| me.eval(&nodes, t, out)),
        }
    }

    /// Imposes the held values at `t0` on u₀ and their rate (a centred difference) on v₀.
    fn initial(&self, mesh: &crate::runtime::fem::mesh::Mesh, t0: f64, u0: &mut [f64], v0: &mut [f64]) {
        let nodes: Vec<Vec<f64>> = (0..mesh.num_nodes()).map(|i| mesh.node(i).to_vec()).collect();
        let n = self.dofs.len();
        let (mut g, mut up, mut down) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let eps = 1e-6 * t0.abs().max(1.0);
        self.eval(&nodes, t0, &mut g);
        self.eval(&nodes, t0 + eps, &mut up);
        self.eval(&nodes, t0 - eps, &mut down);
        for (k, &i) in self.dofs.iter().enumerate() {
            u0[i] = g[k];
            v0[i] = (up[k] - down[k]) / (2.0 * eps);
        }
    }
}

fn simulate(
    opts: &Options,
    pf: &ProblemFile,
    params: &[super::ProblemParam],
    ex: &mut Exprs,
    active: &Active,
    settings: &Settings,
) -> Result<Run, CaseError> {
    let start = Instant::now();
    let p = pf.problem();
    let (mesh, mesh_label) = super::bind::mesh(pf, ex, opts.mesh.as_deref(), opts.cell_size)?;
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let quad = super::bind::settings(pf, ex, &p.quadrature)?;
    let max = crate::compiler::ir::MAX_DEGREE as f64;
    let degree = |name: &str| -> Result<Option<u32>, CaseError> {
        match quad.iter().find(|(n, _)| n == name) {
            None => Ok(None),
            Some((_, v)) if (1.0..=max).contains(v) && v.fract() == 0.0 => Ok(Some(*v as u32)),
            Some((_, v)) => Err(CaseError::Option(format!(
                "{}: quadrature {name} = {v}: a degree is a whole number in [1, {max}]",
                pf.file
            ))),
        }
    };
    let quadrature = Quadrature { cell: degree("cell")?, facet: degree("facet")? };
    let coef_fns = super::bind::coefs(pf, ex)?;
    coef_shapes(pf, active, &coef_fns, mesh.dim())?;
    let lookup = super::bind::coef_lookup(&coef_fns);
    // Without contact, the coefs only the contact law reads are zero (it integrates over no facet).
    let zeros: Vec<(String, usize)> = if super::bind::contact_free(pf) {
        let law = &active.forms.units[active.forms.contact];
        law.coefs().into_iter().map(|(name, rank)| (name, mesh.dim().pow(rank))).collect()
    } else {
        Vec::new()
    };
    let coefs = |name: &str| {
        lookup(name).or_else(|| {
            let (_, len) = zeros.iter().find(|(n, _)| n == name)?;
            Some(crate::runtime::fem::kernel::Coef::constant(vec![0.0; *len]))
        })
    };
    // The contact law's `Gamma_C` is the obstacle's region (`on REGION`, or `Gamma_C`); none
    // without an obstacle or a region `Gamma_C`.
    let contact = super::bind::CONTACT;
    let contact_region: Option<&str> = match p.obstacles.first() {
        Some(o) => Some(o.region.as_ref().map_or(contact, |r| r.name.as_str())),
        None => p.regions.iter().any(|r| r.name.name == contact).then_some(contact),
    };
    let others: Vec<String> = p.regions.iter().map(|r| r.name.name.clone()).filter(|r| r != contact).collect();
    let (constraints, held) = dirichlet(pf, ex, &mesh)?;
    let problem = Problem {
        coefs: &coefs,
        quadrature,
        contact: contact_region,
        regions: &others,
        constraints: constraints.clone(),
        prescribed: held.as_ref().map(|h| h.prescribed(&mesh)),
        mass: opts.mass,
        newton: opts.newton,
    };
    let mut control = Control::new(
        opts.checkpoint_every,
        opts.out.clone(),
        identity(opts, pf, params, active, &mesh, settings),
        opts.resume,
    )?;
    // A static problem is one equilibrium, from u₀ (no initial acceleration to solve for): it
    // binds the tools, and no stepper.
    let statics = p.run_static.is_some();
    if statics && held.is_some() {
        return Err(CaseError::Option(format!(
            "{}: a static problem holds its Dirichlet values at zero (a nonzero held value needs a time run)",
            pf.file
        )));
    }
    let mut runner = if statics {
        Runner::Static(Box::new(crate::simulation::Tools::bind(&asm, problem, active)?))
    } else {
        Runner::Time(Box::new(Simulation::new(&asm, problem, active)?))
    };
    let t0 = settings.t_start;
    // The initial fields take the held values on the held dofs.
    let mut u0 = super::bind::initial(pf, ex, &mesh, "u", t0)?;
    let mut v0 = super::bind::initial(pf, ex, &mesh, "v", t0)?;
    constraints.impose(&mut u0);
    constraints.zero(&mut v0);
    if let Some(h) = &held {
        h.initial(&mesh, t0, &mut u0, &mut v0);
    }
    let mut regions = vec![(contact.to_string(), runner.tools().contact_facets)];
    for name in &others {
        regions.push((name.clone(), asm.region(name)?));
    }
    let binding = Binding { quadrature, regions, dim: mesh.dim() };
    let coef_vals = super::bind::coef_vals(pf, ex)?;
    let reference = bound_reference(pf, ex, active, &mesh, runner.tools().contact_facets, t0)?;
    let mut observer = Observer::new(
        pf,
        ex,
        runner.tools(),
        &active.forms,
        &coefs,
        &binding,
        &coef_vals,
        quadrature.facet.unwrap_or(7),
        reference,
    )?;
    let columns: Vec<String> = observer.names().map(str::to_string).collect();
    let shown = observer.shown();
    let summary_fns = SummaryKeys::new(pf, ex, &columns)?;
    // A column only `at_max` reads (not written, plotted or read by another column or key) is
    // measured only where its maximand reaches a new maximum: the contact radius at the peak
    // force samples the pressure at those rows, not at every step.
    for (column, by) in summary_fns.at_max_columns(&columns) {
        if !p.plots.iter().flat_map(|pl| &pl.columns).any(|c| c.name == columns[column]) {
            observer.defer(column, by);
        }
    }
    let row = |tools: &crate::simulation::Tools, state: State| {
        let t = state.t;
        let (values, switches) = observer.row(tools, &state);
        ((t, values), switches)
    };
    let name = pf.name().to_string();
    let mut snapshots = Snapshots::new(opts.out.as_ref(), opts.vtu_every, &name);
    let (series, switches, iterations, stage_rows, outcome, counters, steps, last) = match &mut runner {
        Runner::Static(tools) => {
            // One equilibrium by the static driver: its single row is the solution.
            let contact = contact_region.ok_or_else(|| {
                CaseError::Option(format!(
                    "{}: a static problem needs its contact (an obstacle, or `Gamma_C`)",
                    pf.file
                ))
            })?;
            let clock = Instant::now();
            let problem = crate::simulation::statics::StaticProblem {
                coefs: &coefs,
                contact,
                contact_degree: quadrature.facet,
                constraints: constraints.clone(),
                newton: opts.newton,
            };
            let solution = crate::simulation::statics::solve(&asm, problem, &active.forms, u0)?;
            let seconds = clock.elapsed().as_secs_f64();
            let newton = solution.newton.iterations();
            let (row, switches) =
                row(tools, State { t: t0, u: &solution.u, v: None, newton, before: None, stage: false });
            snapshots.write(tools, 0, t0, &solution.u, &vec![0.0; n])?;
            let outcome = crate::simulation::Outcome {
                step_seconds: vec![seconds],
                cuts: 0,
                stopped: None,
                resumed: None,
                energy_growth: 0.0,
            };
            let last = (t0, solution.u);
            (vec![row], vec![switches], vec![newton], Vec::new(), outcome, solution.counters, 0, last)
        }
        Runner::Time(sim) => {
            sim.initialize_at(t0, u0, v0)?;
            let first = State { t: t0, u: &sim.states[0], v: sim.velocity(), newton: 0, before: None, stage: false };
            let (first, first_switches) = row(&sim.tools, first);
            let mut series = vec![first];
            let mut switches = vec![first_switches];
            // Newton iterations of each row's step (0 for the initial state).
            let mut iterations: Vec<usize> = vec![0];
            let steps = ((settings.t_end - t0) / settings.dt).round() as usize;
            // A scheme without a velocity state: the step's mean velocity.
            let velocity = |states: &[Vec<f64>], v_index: Option<usize>, before: &[f64], dt: f64| -> Vec<f64> {
                match v_index {
                    Some(i) => states[i].clone(),
                    None => states[0].iter().zip(before).map(|(a, b)| (a - b) / dt).collect(),
                }
            };
            let v_index = sim.v_index;
            let stage_rows: RefCell<Vec<(String, f64, Vec<f64>)>> = RefCell::new(Vec::new());
            let (mut saved_rows, mut saved_stages, mut saved_snapshots) = (0, 0, 0);
            match control.observer() {
                Some(records) => {
                    let stages = sim.stepper.desc().stages;
                    series.clear();
                    iterations.clear();
                    switches.clear();
                    for bytes in records {
                        let record: Record = postcard::from_bytes(bytes).map_err(|e| {
                            CaseError::Option(format!("the checkpoint's record of the run is damaged ({e})"))
                        })?;
                        series.extend(record.series);
                        iterations.extend(record.iterations);
                        switches.extend(record.switches);
                        for (stage, t, values) in record.stages {
                            if !stages.iter().any(|s| s.name == stage) {
                                return Err(CaseError::Option(format!(
                                    "the checkpoint has a stage `{stage}`, which this scheme has not"
                                )));
                            }
                            stage_rows.borrow_mut().push((stage, t, values));
                        }
                        snapshots.extend_written(record.snapshots);
                    }
                    (saved_rows, saved_stages, saved_snapshots) =
                        (series.len(), stage_rows.borrow().len(), snapshots.written().len());
                }
                None => snapshots.write(
                    &sim.tools,
                    0,
                    t0,
                    &sim.states[0],
                    &velocity(&sim.states, v_index, &sim.states[0], settings.dt),
                )?,
            }
            let names = sim.stepper.desc().states;
            let outcome = sim.run(
                t0,
                settings.dt,
                steps,
                opts.progress,
                &mut control,
                &mut |tools, stage, v_index| {
                    if let Some(u) = stage.value_of(names[0]) {
                        let v = v_index.and_then(|i| stage.value_of(names[i]));
                        let ((t, values), _) =
                            row(tools, State { t: stage.time, u, v, newton: 0, before: None, stage: true });
                        stage_rows.borrow_mut().push((stage.name.to_string(), t, values));
                    }
                },
                &mut |tools, step, record| {
                    let v = v_index.map(|i| step.states[i].as_slice());
                    let state = State {
                        t: step.t,
                        u: &step.states[0],
                        v,
                        newton: step.report.iterations(),
                        before: Some((step.before, step.dt)),
                        stage: false,
                    };
                    let (values, active) = row(tools, state);
                    series.push(values);
                    switches.push(active);
                    iterations.push(step.report.iterations());
                    snapshots.write(
                        tools,
                        step.k,
                        step.t,
                        &step.states[0],
                        &velocity(step.states, v_index, step.before, step.dt),
                    )?;
                    if let Some(record) = record {
                        let stages = stage_rows.borrow();
                        *record = postcard::to_stdvec(&Record {
                            series: series[saved_rows..].to_vec(),
                            iterations: iterations[saved_rows..].to_vec(),
                            switches: switches[saved_rows..].to_vec(),
                            stages: stages[saved_stages..].to_vec(),
                            snapshots: snapshots.written()[saved_snapshots..].to_vec(),
                        })
                        .map_err(|e| CaseError::Option(format!("cannot encode the checkpoint: {e}")))?;
                        (saved_rows, saved_stages, saved_snapshots) =
                            (series.len(), stages.len(), snapshots.written().len());
                    }
                    Ok(())
                },
            )?;
            let stage_rows = stage_rows.into_inner();
            let last = (series.last().map_or(t0, |r| r.0), sim.states[0].clone());
            (series, switches, iterations, stage_rows, outcome, sim.stepper.counters(), steps, last)
        }
    };
    snapshots.finish()?;
    let wall = start.elapsed().as_secs_f64();
    let mut summary = Summary::default();
    let mut put = |k: &str, v: serde_json::Value| summary.keys.push((k.to_string(), v));
    put("case", name.clone().into());
    put("problem", pf.file.clone().into());
    put("scheme", if statics { "static".into() } else { active.scheme_name().into() });
    put("contact", active.forms.contact_name().into());
    put("interpreted", json(&active.interpreted()));
    put("params", json(&all_params(active, params, pf)));
    put("mass", json(&opts.mass));
    put("cell_size", json(&opts.cell_size));
    put("mesh", mesh_label.clone().into());
    put("cells", mesh.num_cells().into());
    put("dofs", n.into());
    put("dt", json(&settings.dt));
    put("steps", steps.into());
    // The time reached (t_end, or where the run stopped).
    put("t_end", json(&series.last().map_or(t0, |r| r.0)));
    let own = summary_fns.values(&series);
    for (k, v) in &own {
        put(k, json(v));
    }
    put("newton_total", iterations.iter().sum::<usize>().into());
    put("newton_max", iterations.iter().max().copied().unwrap_or(0).into());
    put("wall_seconds", json(&wall));
    put("seconds_per_step", json(&(wall / steps.max(1) as f64)));
    put("stepping_seconds", json(&outcome.step_seconds.iter().sum::<f64>()));
    put("step_median_seconds", json(&crate::resources::median(outcome.step_seconds.clone())));
    put("factorizations", counters.numeric.into());
    put("symbolic_factorizations", counters.symbolic.into());
    put("low_rank_updates", counters.updates.into());
    put("matrix_nnz", asm.pattern().nnz().into());
    let factor_nnz = match &runner {
        Runner::Time(sim) => sim.stepper.factor_nnz(),
        Runner::Static(_) => None,
    };
    put("factor_nnz", json(&factor_nnz));
    // An explicit scheme's critical step, estimated at the start (docs/language.md).
    if let Runner::Time(sim) = &runner
        && let Some(stable) = sim.stable
    {
        put("stable_dt", json(&stable.dt));
        put("omega_max", json(&stable.omega_max));
    }
    put("solver", json(&opts.newton.solver));
    put("krylov_iterations", counters.iterations.into());
    put("peak_memory_bytes", json(&crate::resources::peak_memory()));
    put("step_cuts", outcome.cuts.into());
    if !statics {
        put("energy_growth", json(&outcome.energy_growth));
    }
    if let Some(stopped) = &outcome.stopped {
        put("stopped", stopped.to_string().into());
    }
    if let Some(resumed) = &outcome.resumed {
        put("resumed", json(resumed));
    }
    // Why a key is null: undefined on this run (0/0 or no row where `first` finds one).
    let notes: Vec<String> = own
        .iter()
        .filter(|(_, v)| !v.is_some_and(f64::is_finite))
        .map(|(k, _)| {
            let at = p.summary.iter().find(|d| d.name.name == *k).map(|d| d.span);
            let line = at.map_or(0, |s| pf.program.unit.sources.line_col(s.file, s.start).0);
            format!("{k} is undefined on this run (its expression at {}:{line} has no value)", pf.file)
        })
        .collect();
    if !notes.is_empty() {
        put("notes", json(&notes));
    }
    summary.own = own.into_iter().map(|(k, _)| k).collect();
    let run = Run { summary, columns, rows: series, switches, stages: stage_rows };
    if let Some(dir) = &opts.out {
        write_outputs(dir, pf, &run, &shown)?;
        // The reference's figures of the last state (Hertz's pressure profile).
        observer
            .write_reference(dir, runner.tools(), &last.1, last.0)
            .map_err(|source| CaseError::Write { path: dir.display().to_string(), source })?;
    }
    if let Some(e) = outcome.stopped {
        return Err(e);
    }
    Ok(run)
}

/// What runs a problem: the stepper (a time run), or a static problem's tools alone (its one
/// equilibrium is the static driver's).
enum Runner<'m> {
    Time(Box<Simulation<'m>>),
    Static(Box<crate::simulation::Tools<'m>>),
}

impl<'m> Runner<'m> {
    fn tools(&self) -> &crate::simulation::Tools<'m> {
        match self {
            Runner::Time(sim) => &sim.tools,
            Runner::Static(tools) => tools,
        }
    }
}

/// A run's summary: keys in order.
#[derive(Default)]
pub struct Summary {
    pub keys: Vec<(String, serde_json::Value)>,
    /// The problem's own keys (`summary NAME = ...`).
    pub own: Vec<String>,
}

impl Summary {
    pub fn get(&self, key: &str) -> Option<&serde_json::Value> {
        self.keys.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    /// A number of the summary (`None` when absent or null).
    pub fn number(&self, key: &str) -> Option<f64> {
        self.get(key)?.as_f64()
    }

    /// A key of the summary, as its type (null when absent).
    pub fn field<T: serde::de::DeserializeOwned>(&self, k: &str) -> Result<T, CaseError> {
        let v = self.get(k).cloned().unwrap_or(serde_json::Value::Null);
        serde_json::from_value(v).map_err(|e| CaseError::Option(format!("the summary's `{k}`: {e}")))
    }
}

impl Serialize for Summary {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.keys.len()))?;
        for (k, v) in &self.keys {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

/// A value as JSON (non-finite numbers become null, as serde_json writes them).
fn json<T: Serialize + ?Sized>(v: &T) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or(serde_json::Value::Null)
}

/// Every param in effect: the problem's, the scheme's and the form files'.
fn all_params(active: &Active, params: &[super::ProblemParam], pf: &ProblemFile) -> BTreeMap<String, ParamValue> {
    let mut out = active.forms.params.values();
    for q in params {
        let declared = pf.problem().params.iter().find(|d| d.name.name == q.name).map(|d| d.span);
        let line = declared.map_or(0, |s| pf.program.unit.sources.line_col(s.file, s.start).0);
        out.insert(
            format!("{}.{}", pf.name(), q.name),
            ParamValue { value: q.value, source: q.source, declared: format!("{}:{line}", pf.file) },
        );
    }
    out
}

/// What a checkpoint keeps of the run: what is new since the checkpoint before.
#[derive(Serialize, Deserialize)]
struct Record {
    series: Vec<(f64, Vec<f64>)>,
    iterations: Vec<usize>,
    switches: Vec<Vec<bool>>,
    stages: Vec<(String, f64, Vec<f64>)>,
    snapshots: Vec<(f64, String)>,
}

/// What a resumed run must share with its checkpoint.
fn identity(
    opts: &Options,
    pf: &ProblemFile,
    params: &[super::ProblemParam],
    active: &Active,
    mesh: &crate::runtime::fem::mesh::Mesh,
    s: &Settings,
) -> crate::checkpoint::Identity {
    let mut more = vec![
        ("problem file", format!("{} ({:016x})", pf.file, pf.text_hash)),
        ("mass", format!("{:?}", opts.mass)),
        ("cell size", format!("{:?}", opts.cell_size)),
        ("dt", format!("{:?}", s.dt)),
        ("t_start", format!("{:?}", s.t_start)),
        ("t_end", format!("{:?}", s.t_end)),
        ("Newton options", format!("{:?}", opts.newton)),
        ("checkpoint period", opts.checkpoint_every.to_string()),
    ];
    let problem_params: Vec<String> = params.iter().map(|p| format!("{} = {:?}", p.name, p.value)).collect();
    more.push(("problem params", problem_params.join(", ")));
    crate::checkpoint::identity(pf.name(), active, mesh, &more)
}

fn write_outputs(dir: &Path, pf: &ProblemFile, run: &Run, shown: &[bool]) -> Result<(), CaseError> {
    let header: Vec<&str> = std::iter::once("t")
        .chain(run.columns.iter().zip(shown).filter(|(_, s)| **s).map(|(c, _)| c.as_str()))
        .collect();
    let header = header.join(",");
    let line = |t: f64, values: &[f64]| {
        let mut s = format!("{t}");
        for (v, _) in values.iter().zip(shown).filter(|(_, s)| **s) {
            s.push_str(&format!(",{v}"));
        }
        s.push('\n');
        s
    };
    let mut csv = format!("{header}\n");
    run.rows.iter().for_each(|(t, v)| csv.push_str(&line(*t, v)));
    let err = |path: PathBuf| move |source| CaseError::Write { path: path.display().to_string(), source };
    crate::output::write_atomic(&dir.join("series.csv"), csv.as_bytes()).map_err(err(dir.join("series.csv")))?;
    crate::output::write_json(&dir.join("summary.json"), &run.summary).map_err(err(dir.join("summary.json")))?;
    if !run.stages.is_empty() {
        let mut csv = format!("stage,{header}\n");
        for (stage, t, values) in &run.stages {
            csv.push_str(&format!("{stage},{}", line(*t, values)));
        }
        crate::output::write_atomic(&dir.join("stages.csv"), csv.as_bytes()).map_err(err(dir.join("stages.csv")))?;
    }
    let plots = &pf.problem().plots;
    if plots.is_empty() {
        return Ok(());
    }
    use crate::plot::Curve;
    let panels: Vec<(&str, &str, Vec<Curve>)> = plots
        .iter()
        .map(|pl| {
            let curves = pl
                .columns
                .iter()
                .filter_map(|c| {
                    let i = run.columns.iter().position(|n| *n == c.name)?;
                    let points = run.rows.iter().map(|(t, v)| (*t, v[i])).collect();
                    Some(Curve { label: c.name.as_str(), points, dashed: false })
                })
                .collect();
            (pl.title.as_str(), pl.title.as_str(), curves)
        })
        .collect();
    crate::plot::panels(&dir.join(format!("{}.png", pf.name())), "t", &panels)
        .map_err(|e| CaseError::Write { path: dir.display().to_string(), source: std::io::Error::other(e) })
}
