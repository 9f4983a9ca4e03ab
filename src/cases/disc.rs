//! `signorini run disc`: the elastic disc bouncing on a rigid plane (docs/mathematics.md §6). A disc of
//! radius 10 centred at (0, 12) falls from rest under f = (0, −0.1) onto {y = 0}; plane strain
//! with λ = μ = 20 (E = 50, ν = 1/4), ρ = 1; curved P2 triangles; no Dirichlet condition.

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use super::CaseError;
use super::bar::MassChoice;
use crate::driver::{Active, ParamValue, Setup};
use crate::runtime::assembly::{Assembler, Quadrature};
use crate::runtime::evaluate::facet_samples;
use crate::runtime::kernel::Coef;
use crate::runtime::library::Binding;
use crate::runtime::linalg::{Matrix, Structure};
use crate::runtime::mesh::{CellSize, Mesh, disc::disc, gmsh};
use crate::runtime::newton::NewtonOptions;
use crate::runtime::problem::Constraints;
use crate::runtime::scheme::{MatrixForm, Stepper};

/// Gravity of the benchmark.
pub const GRAVITY: f64 = 0.1;
/// Cell and contact-facet quadrature degrees (12-point triangle rule; 4 Gauss points per edge).
const QUADRATURE: Quadrature = Quadrature { cell: Some(6), facet: Some(7) };
/// The disc's material (λ = μ = 20) and its Nitsche/penalty parameter, over the files' defaults.
pub const OVERRIDES: &[(&str, f64)] = &[("E", 50.0), ("nu", 0.25), ("rho", 1.0), ("gamma0", 1000.0)];

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Scheme, contact law, extra forms and params.
    pub setup: Setup,
    pub mass: MassChoice,
    /// What `h` means in γ = γ0/h.
    pub cell_size: CellSize,
    /// A Gmsh file; the built-in curved disc generator otherwise.
    pub mesh: Option<PathBuf>,
    /// Mesh size of the built-in generator.
    pub h: f64,
    pub dt: f64,
    pub t_end: f64,
    pub newton: NewtonOptions,
    pub out: Option<PathBuf>,
    /// Write a VTU snapshot every this many steps (0: none) into `out`/vtu, with disc.pvd.
    pub vtu_every: usize,
    /// Show a progress bar on long runs (when stdout is a terminal).
    pub progress: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            setup: Setup::default(),
            mass: MassChoice::Consistent,
            cell_size: CellSize::Diameter,
            mesh: None,
            h: 1.0,
            dt: 0.02,
            t_end: 20.0,
            newton: NewtonOptions::default(),
            out: None,
            vtu_every: 0,
            progress: false,
        }
    }
}

/// One row of `series.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub t: f64,
    pub energy: f64,
    /// ½vᵀMv (with the mass the scheme uses).
    pub kinetic: f64,
    pub energy_aug: f64,
    /// Mass-weighted mean of u_y (the centre of mass).
    pub uy_mean: f64,
    /// Plain mean of the nodal u_y (GetFEM's benchmark reports this one).
    pub uy_mean_nodal: f64,
    /// Mass-weighted mean of v_y: the centre of mass's velocity (NaN for a scheme without `v`).
    pub vy_mean: f64,
    pub uy_lowest: f64,
    pub fy_contact: f64,
    pub active_points: usize,
    /// The contact switches at every contact quadrature point (the active set).
    #[serde(skip)]
    pub switches: Vec<bool>,
    pub penetration: f64,
    pub newton: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub case: &'static str,
    pub scheme: String,
    /// The contact law (its file stem).
    pub contact: String,
    /// Files of the run compiled at run time (given by path, not in the library).
    pub interpreted: Vec<String>,
    /// Every param of the scheme and form files, with its value and where it comes from.
    pub params: std::collections::BTreeMap<String, ParamValue>,
    pub mass: MassChoice,
    pub cell_size: CellSize,
    pub mesh: String,
    pub cells: usize,
    pub dofs: usize,
    pub dt: f64,
    pub steps: usize,
    /// Time of the first step that ends with an active contact point.
    pub first_contact: Option<f64>,
    pub max_penetration: f64,
    pub min_uy_mean: f64,
    pub energy_aug_initial: f64,
    pub energy_aug_final: f64,
    /// The largest kinetic energy ½vᵀMv over the run (at impact): the disc's energy scale, as
    /// E_aug(0) = 0.
    pub kinetic_energy_max: f64,
    pub newton_total: usize,
    pub newton_max: usize,
    pub wall_seconds: f64,
    pub seconds_per_step: f64,
    /// Time inside the time stepper alone (no setup, measurements or output), in total and
    /// the median over steps.
    pub stepping_seconds: f64,
    pub step_median_seconds: f64,
    /// Numeric factorizations of the stage Jacobians (the rest of the Newton iterations reuse one).
    pub factorizations: usize,
}

pub struct Run {
    pub summary: Summary,
    pub series: Vec<Row>,
    /// Multi-stage schemes: the measures at every intermediate stage (`stages.csv`); the
    /// Newton column is 0 there (the step's count is in `series`).
    pub stages: Vec<StageRow>,
}

/// The measures at an intermediate stage's time.
#[derive(Clone, Debug)]
pub struct StageRow {
    /// The stage's name in the scheme's file.
    pub stage: &'static str,
    pub row: Row,
}

/// The mesh: read or generated, validated, with its `contact` region (the Gmsh group of that
/// name, else the facets whose outward normal has n_y < 0).
pub fn mesh(opts: &Options) -> Result<Mesh, CaseError> {
    let mut mesh = match &opts.mesh {
        Some(path) => gmsh::read(path)?,
        None => {
            if !(opts.h > 0.05 && opts.h <= 10.0) {
                return Err(CaseError::Option(format!("--h must be in (0.05, 10], not {}", opts.h)));
            }
            disc(10.0, [0.0, 12.0], opts.h)
        }
    };
    if mesh.dim() != 2 {
        return Err(CaseError::Option(format!("the disc case needs a 2D mesh, not {}D", mesh.dim())));
    }
    if mesh.region("contact").is_err() {
        mesh.add_region_where("contact", |n, _| n[1] < 0.0);
    }
    mesh.set_cell_size(opts.cell_size);
    mesh.validate()?;
    Ok(mesh)
}

pub fn run(opts: &Options) -> Result<Run, CaseError> {
    let positive = |x: f64| x > 0.0 && x.is_finite();
    if !positive(opts.dt) || !positive(opts.t_end) || opts.t_end / opts.dt > 1e7 {
        return Err(CaseError::Option("--dt and --t-end must be positive, with at most 10⁷ steps".into()));
    }
    let active = Active::resolve(&opts.setup, OVERRIDES)?;
    simulate(opts, &active)
}

/// Case data: gravity, the gap to {y = 0} and the obstacle normal −e_y.
fn coefs(name: &str) -> Option<Coef> {
    match name {
        "f" => Some(Coef::constant(vec![0.0, -GRAVITY])),
        "g" => Some(Coef::function(1, |x, _, out| out[0] = x[1])),
        "nc" => Some(Coef::constant(vec![0.0, -1.0])),
        _ => None,
    }
}

fn quad(a: &Matrix, x: &[f64], y: &[f64]) -> f64 {
    let mut ay = vec![0.0; y.len()];
    a.mul_vec(y, &mut ay);
    x.iter().zip(&ay).map(|(p, q)| p * q).sum()
}

fn simulate(opts: &Options, active: &Active) -> Result<Run, CaseError> {
    let start = Instant::now();
    let mesh = mesh(opts)?;
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let contact_facets = asm.region("contact")?;
    let binding = Binding { quadrature: QUADRATURE, regions: vec![("Gamma_C".into(), contact_facets)], dim: 2 };
    let mut inst = active.forms.instantiate(&coefs, &binding)?;
    let mut forms = active.scheme_forms(&mut inst)?;
    let missing = |what: &str| {
        CaseError::Option(format!("the disc measures `{what}`, which the form files in use do not provide"))
    };
    let contact_energy = inst.take_functional("contact_energy");
    let probe = active.forms.instantiate(&coefs, &binding)?.take_form("contact").ok_or_else(|| missing("contact"))?;
    let von_mises = inst.take_functional("von_mises");
    let cell_measure = inst.take_functional("measure");
    // Consistent mass and stiffness, the load: for the measurements.
    let zero = vec![0.0; n];
    let slot = |forms: &[(&str, Box<dyn crate::runtime::scheme::BoundForm + '_>)], name: &str| {
        forms.iter().position(|(s, _)| *s == name).ok_or_else(|| missing(name))
    };
    let mut mass = asm.zero_matrix();
    forms[slot(&forms, "mass")?].1.tangent(&asm, &[&zero], 0, 0.0, &mut mass);
    let mut stiffness = asm.zero_matrix();
    forms[slot(&forms, "stiffness")?].1.tangent(&asm, &[&zero], 0, 0.0, &mut stiffness);
    let mut load = vec![0.0; n];
    forms[slot(&forms, "load")?].1.residual(&asm, &[], 0.0, &mut load);
    let redistributed = opts.mass == MassChoice::Redistributed;
    let constraints = Constraints::none(n);
    let contact_nodes = mesh.region_nodes(mesh.region("contact")?);
    let energy_mass = if redistributed {
        let r = crate::runtime::redistribute::redistribute(&mesh, &mass, &contact_nodes)
            .map_err(|e| CaseError::Option(e.to_string()))?;
        let i = slot(&forms, "mass")?;
        forms[i] = ("mass", Box::new(MatrixForm { name: "mass".into(), matrix: r.matrix.clone() }));
        r.matrix
    } else {
        mass.clone()
    };
    let mut stepper =
        Stepper::new(active.time_scheme()?, &asm, forms, constraints.clone(), Structure::Auto, opts.newton)?;
    if redistributed {
        let mut initial = constraints;
        for &c in &contact_nodes {
            initial.fix(2 * c as usize);
            initial.fix(2 * c as usize + 1);
        }
        stepper.initial_constraints = Some(initial);
    }
    let names = stepper.desc().states;
    let mut states: Vec<Vec<f64>> = names.iter().map(|_| vec![0.0; n]).collect();
    stepper.initialize(&mut states, 0.0)?;
    let v_index = names.iter().position(|s| *s == "v");
    let ey: Vec<f64> = (0..n).map(|i| if i % 2 == 1 { 1.0 } else { 0.0 }).collect();
    let mut mass_ey = vec![0.0; n];
    mass.mul_vec(&ey, &mut mass_ey);
    let total_mass: f64 = mass_ey.iter().zip(&ey).map(|(a, b)| a * b).sum();
    let lowest = (0..mesh.num_nodes()).min_by(|&a, &b| mesh.node(a)[1].total_cmp(&mesh.node(b)[1])).expect("nodes");
    let measure = |u: &[f64], v: Option<&[f64]>, newton: usize, t: f64| -> Row {
        let kinetic = v.map_or(0.0, |v| 0.5 * quad(&energy_mass, v, v));
        let energy = 0.5 * quad(&stiffness, u, u) + kinetic - load.iter().zip(u).map(|(l, x)| l * x).sum::<f64>();
        let mut c = vec![0.0; n];
        probe.residual(&asm, &[u], t, &mut c);
        let mut switches = Vec::new();
        probe.switches(&asm, &[u], 0, t, &mut switches);
        let samples = facet_samples(&mesh, contact_facets, QUADRATURE.facet.unwrap_or(7), u);
        let penetration = samples.iter().map(|s| (-s.value[1] - s.x[1]).max(0.0)).fold(0.0, f64::max);
        Row {
            t,
            energy,
            kinetic,
            energy_aug: energy + contact_energy.as_ref().map_or(f64::NAN, |e| e.value(&asm, &[u], 0.0)),
            // Area-weighted mean of u_y: e_yᵀ M u / e_yᵀ M e_y.
            uy_mean: mass_ey.iter().zip(u).map(|(a, b)| a * b).sum::<f64>() / total_mass,
            uy_mean_nodal: u.iter().skip(1).step_by(2).sum::<f64>() / (n / 2) as f64,
            vy_mean: v.map_or(f64::NAN, |v| mass_ey.iter().zip(v).map(|(a, b)| a * b).sum::<f64>() / total_mass),
            uy_lowest: u[2 * lowest + 1],
            // C(u) tested with e_y is minus the upward force on the disc.
            fy_contact: -c.iter().skip(1).step_by(2).sum::<f64>(),
            active_points: switches.iter().filter(|b| **b).count(),
            switches,
            penetration,
            newton,
        }
    };
    let mut series = vec![measure(&states[0], v_index.map(|i| states[i].as_slice()), 0, 0.0)];
    let steps = (opts.t_end / opts.dt).round() as usize;
    let mut progress = crate::progress::Progress::new(steps, opts.progress);
    let vtu_dir = opts.out.as_ref().filter(|_| opts.vtu_every > 0).map(|d| d.join("vtu"));
    let mut snapshots: Vec<(f64, String)> = Vec::new();
    let mut snapshot = |k: usize, t: f64, u: &[f64], v: &[f64]| -> Result<(), CaseError> {
        let Some(dir) = &vtu_dir else { return Ok(()) };
        if !k.is_multiple_of(opts.vtu_every) {
            return Ok(());
        }
        let name = format!("disc_{k:06}.vtu");
        let vm = match (&von_mises, &cell_measure) {
            (Some(vm), Some(measure)) => {
                let area = measure.cell_values(&asm, &[], 0.0);
                vm.cell_values(&asm, &[u], 0.0).iter().zip(&area).map(|(v, a)| v / a).collect()
            }
            _ => vec![f64::NAN; mesh.num_cells()],
        };
        let point = [
            crate::vtu::Field { name: "displacement", components: 2, values: u },
            crate::vtu::Field { name: "velocity", components: 2, values: v },
        ];
        let cell = [crate::vtu::Field { name: "von_mises", components: 1, values: &vm }];
        let path = dir.join(&name);
        crate::vtu::write(&path, &mesh, &point, &cell)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })?;
        snapshots.push((t, format!("vtu/{name}")));
        Ok(())
    };
    let velocity = |states: &[Vec<f64>], before: &[f64]| -> Vec<f64> {
        match v_index {
            Some(i) => states[i].clone(),
            None => states[0].iter().zip(before).map(|(a, b)| (a - b) / opts.dt).collect(),
        }
    };
    snapshot(0, 0.0, &states[0], &velocity(&states, &states[0]))?;
    let mut step_times = Vec::with_capacity(steps);
    // Multi-stage schemes: the state at each intermediate stage's time (stages.csv).
    let desc_stages = stepper.desc().stages;
    let intermediate: Vec<&str> = desc_stages.iter().rev().skip(1).map(|s| s.name).collect();
    let mut stage_rows: Vec<StageRow> = Vec::new();
    for k in 0..steps {
        progress.tick(k);
        let t = k as f64 * opts.dt;
        let before = states[0].clone();
        let clock = Instant::now();
        let report = stepper.step_observed(&mut states, t, opts.dt, &mut |stage| {
            if let (true, Some(u)) = (intermediate.contains(&stage.name), stage.value_of(names[0])) {
                let v = v_index.and_then(|i| stage.value_of(names[i]));
                stage_rows.push(StageRow { stage: stage.name, row: measure(u, v, 0, stage.time) });
            }
        })?;
        step_times.push(clock.elapsed().as_secs_f64());
        series.push(measure(&states[0], v_index.map(|i| states[i].as_slice()), report.iterations(), t + opts.dt));
        snapshot(k + 1, t + opts.dt, &states[0], &velocity(&states, &before))?;
    }
    if let (Some(out), false) = (&opts.out, snapshots.is_empty()) {
        let path = out.join("disc.pvd");
        crate::vtu::write_collection(&path, &snapshots)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })?;
    }
    progress.finish();
    let wall = start.elapsed().as_secs_f64();
    let last = series.last().expect("initial row");
    let summary = Summary {
        case: "disc",
        scheme: active.scheme_name().to_string(),
        contact: active.forms.contact_name().to_string(),
        interpreted: active.interpreted(),
        params: active.forms.params.values(),
        mass: opts.mass,
        cell_size: opts.cell_size,
        mesh: opts.mesh.as_ref().map_or_else(|| format!("built-in disc, h = {}", opts.h), |p| p.display().to_string()),
        cells: mesh.num_cells(),
        dofs: n,
        dt: opts.dt,
        steps,
        first_contact: series.iter().find(|r| r.active_points > 0).map(|r| r.t),
        max_penetration: series.iter().map(|r| r.penetration).fold(0.0, f64::max),
        min_uy_mean: series.iter().map(|r| r.uy_mean).fold(f64::INFINITY, f64::min),
        energy_aug_initial: series[0].energy_aug,
        energy_aug_final: last.energy_aug,
        kinetic_energy_max: series.iter().map(|r| r.kinetic).fold(0.0, f64::max),
        newton_total: series.iter().map(|r| r.newton).sum(),
        newton_max: series.iter().map(|r| r.newton).max().unwrap_or(0),
        wall_seconds: wall,
        seconds_per_step: wall / steps.max(1) as f64,
        stepping_seconds: step_times.iter().sum(),
        step_median_seconds: crate::bench::median(step_times),
        factorizations: stepper.counters().numeric,
    };
    if let Some(dir) = &opts.out {
        write_outputs(dir, &summary, &series, &stage_rows)?;
    }
    Ok(Run { summary, series, stages: stage_rows })
}

fn write_outputs(
    dir: &std::path::Path,
    summary: &Summary,
    series: &[Row],
    stages: &[StageRow],
) -> Result<(), CaseError> {
    let mut csv = String::from(
        "t,energy,energy_aug,uy_mean,uy_mean_nodal,vy_mean,uy_lowest,fy_contact,active_points,penetration,newton\n",
    );
    for r in series {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{}\n",
            r.t,
            r.energy,
            r.energy_aug,
            r.uy_mean,
            r.uy_mean_nodal,
            r.vy_mean,
            r.uy_lowest,
            r.fy_contact,
            r.active_points,
            r.penetration,
            r.newton
        ));
    }
    let err = |path: std::path::PathBuf| move |source| CaseError::Write { path: path.display().to_string(), source };
    crate::output::write_atomic(&dir.join("series.csv"), csv.as_bytes()).map_err(err(dir.join("series.csv")))?;
    crate::output::write_json(&dir.join("summary.json"), summary).map_err(err(dir.join("summary.json")))?;
    if !stages.is_empty() {
        let mut csv = String::from(
            "stage,t,energy,energy_aug,uy_mean,uy_mean_nodal,vy_mean,fy_contact,active_points,penetration\n",
        );
        for StageRow { stage, row: r } in stages {
            csv.push_str(&format!(
                "{stage},{},{},{},{},{},{},{},{},{}\n",
                r.t,
                r.energy,
                r.energy_aug,
                r.uy_mean,
                r.uy_mean_nodal,
                r.vy_mean,
                r.fy_contact,
                r.active_points,
                r.penetration
            ));
        }
        crate::output::write_atomic(&dir.join("stages.csv"), csv.as_bytes()).map_err(err(dir.join("stages.csv")))?;
    }
    use crate::plot::Curve;
    let pts = |f: &dyn Fn(&Row) -> f64| series.iter().map(|r| (r.t, f(r))).collect::<Vec<_>>();
    let plot_err = |e: String| CaseError::Write { path: dir.display().to_string(), source: std::io::Error::other(e) };
    let aug = "E + contact energy";
    crate::plot::panels(
        &dir.join("disc.png"),
        "t",
        &[
            (
                "energies",
                "energy",
                vec![
                    Curve { label: "E", points: pts(&|r| r.energy), dashed: false },
                    Curve { label: aug, points: pts(&|r| r.energy_aug), dashed: false },
                ],
            ),
            (
                "vertical displacement",
                "u_y",
                vec![
                    Curve { label: "mean", points: pts(&|r| r.uy_mean), dashed: false },
                    Curve { label: "lowest point", points: pts(&|r| r.uy_lowest), dashed: false },
                ],
            ),
            ("contact force", "F_y", vec![Curve { label: "F_y", points: pts(&|r| r.fy_contact), dashed: false }]),
            (
                "Newton iterations",
                "iterations",
                vec![Curve { label: "per step", points: pts(&|r| r.newton as f64), dashed: false }],
            ),
        ],
    )
    .map_err(plot_err)
}
