//! `signorini run hertz-impact`: a ball of radius 10 (the quarter x, y ≥ 0, normal
//! displacement held on the symmetry planes) hits the rigid plane at speed v, without gravity,
//! in Hertz's quasi-static regime (δ_max/R ≤ 2 %, contact time ≥ 10 R/c_p): the contact
//! duration, the peak force and the contact radius at the peak against Hertz's impact formulas.

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use super::meshes;
use crate::cases::CaseError;
use crate::driver::{Active, ParamValue, Setup};
use crate::references::hertz::closed_form::{Impact, Material};
use crate::references::hertz::profile;
use crate::runtime::assembly::{Assembler, Quadrature};
use crate::runtime::mesh::CellSize;
use crate::runtime::newton::NewtonOptions;
use crate::simulation::MassChoice;
use crate::simulation::{Problem, Simulation, Tools};

/// The impact speed of the default run: δ_max/R = 0.29 %, contact time 26.6 R/c_p. Faster
/// impacts are further from Hertz's quasi-static theory, since the contact time is then only a
/// few periods of the ball's lowest vibration (measured at this mesh: peak force +5.4 % at
/// v = 0.02, +3.0 % at 0.005, +2.4 % at 0.0025).
pub const SPEED: f64 = 0.0025;
/// Steps per Hertz contact time in the default run.
pub const STEPS_PER_CONTACT: f64 = 200.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Scheme, contact law, material and params.
    pub setup: Setup,
    /// Level of the built-in graded quarter ball.
    pub level: usize,
    pub mesh: Option<PathBuf>,
    pub speed: f64,
    /// Time step; default: Hertz's contact time / 200.
    pub dt: Option<f64>,
    pub mass: MassChoice,
    pub cell_size: CellSize,
    pub newton: NewtonOptions,
    pub out: Option<PathBuf>,
    pub progress: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            setup: Setup::default(),
            level: 0,
            mesh: None,
            speed: SPEED,
            dt: None,
            mass: MassChoice::Consistent,
            cell_size: CellSize::Diameter,
            newton: NewtonOptions::default(),
            out: None,
            progress: false,
        }
    }
}

/// Contact duration, peak force, contact radius at the peak force.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Figures {
    pub contact_duration: f64,
    pub peak_force: f64,
    pub contact_radius: f64,
}

/// How far the run is in Hertz's quasi-static regime.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Regime {
    /// δ_max / R (Hertz); the theory wants it small (≤ 2 %, say).
    pub indentation_ratio: f64,
    /// Hertz's contact time over R / c_p; the theory wants it large (≥ 10, say).
    pub contact_time_over_wave_time: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub case: &'static str,
    pub scheme: String,
    pub contact: String,
    pub params: std::collections::BTreeMap<String, ParamValue>,
    pub radius: f64,
    pub young: f64,
    pub poisson: f64,
    pub density: f64,
    pub impact_velocity: f64,
    pub mesh: String,
    pub cells: usize,
    pub dofs: usize,
    pub dt: f64,
    pub steps: usize,
    pub regime: Regime,
    pub measured: Figures,
    pub hertz: Figures,
    /// (measured − Hertz) / Hertz.
    pub relative_error: Figures,
    /// The centre of mass's rebound speed over the impact speed (1 for Hertz; the elastic
    /// waves left in the ball take the rest).
    pub restitution: f64,
    pub newton_iterations: usize,
    pub wall_seconds: f64,
}

/// One step of the series.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    pub t: f64,
    /// The vertical contact force on the whole ball.
    pub force: f64,
    /// Contact quadrature points whose switch is on (the ball touches when there are any:
    /// the force's sign alone is round-off before contact, from Nitsche's unswitched term).
    pub active_points: usize,
    /// The centre of mass's vertical velocity.
    pub velocity: f64,
    pub energy_aug: f64,
}

pub struct Run {
    pub summary: Summary,
    pub series: Vec<Row>,
}

/// Runs the case; writes series.csv, summary.json and force.png into `opts.out` if set.
pub fn run(opts: &Options) -> Result<Run, CaseError> {
    let start = Instant::now();
    if !(opts.speed > 0.0 && opts.speed.is_finite()) {
        return Err(CaseError::Option(format!("--speed must be a positive number, not {}", opts.speed)));
    }
    let (mut mesh, mesh_name) = meshes::load(3, opts.level, opts.mesh.as_deref())?;
    mesh.set_cell_size(opts.cell_size);
    let active = Active::resolve(&opts.setup, super::OVERRIDES)?;
    let material: Material = super::material(&active.forms)?;
    let radius = meshes::RADIUS;
    let hertz = Impact::new(radius, &material, opts.speed);
    let dt = opts.dt.unwrap_or(hertz.contact_duration / STEPS_PER_CONTACT);
    if !(dt > 0.0 && dt < hertz.contact_duration) {
        return Err(CaseError::Option(format!(
            "--dt must be in (0, {:.4}) (Hertz's contact time), not {dt}",
            hertz.contact_duration
        )));
    }
    // The first contact 2.5 steps after the start: free flight is exact, so it begins at a
    // known time, between two steps.
    let gap0 = 2.5 * dt * opts.speed;
    let coefs = crate::cases::above_plane(3, gap0, 0.0);
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let problem = Problem {
        coefs: &coefs,
        quadrature: Quadrature::default(),
        contact: Some(meshes::CONTACT),
        regions: &[],
        constraints: meshes::symmetry(&mesh)?,
        prescribed: None,
        mass: opts.mass,
        newton: opts.newton,
    };
    let mut sim = Simulation::new(&asm, problem, &active)?;
    let (Some(_), Some(_)) = (&sim.tools.probe, &sim.tools.contact_pressure) else {
        return Err(CaseError::Option(
            "the impact measures `contact` and `contact_pressure`, which the files in use do not provide".into(),
        ));
    };
    let v0: Vec<f64> = (0..n).map(|i| if i % 3 == 2 { -opts.speed } else { 0.0 }).collect();
    sim.initialize_at(0.0, vec![0.0; n], v0)?;
    let vertical_mean = sim.tools.axis_mean(2);
    let row = |tools: &Tools, u: &[f64], v: Option<&[f64]>, t: f64| Row {
        t,
        force: meshes::copies(3) * tools.contact_force(u, t)[2],
        active_points: tools.contact_switches(u, t).iter().filter(|b| **b).count(),
        velocity: v.map_or(f64::NAN, |v| vertical_mean.of(v)),
        energy_aug: tools.energy(u, v) + tools.value(&tools.contact_energy, u),
    };
    let mut series = vec![row(&sim.tools, &sim.states[0], sim.velocity(), 0.0)];
    let steps = ((gap0 / opts.speed + 1.3 * hertz.contact_duration) / dt).ceil() as usize;
    let (mut peak, mut peak_state, mut newton) = (0.0, Vec::new(), 0);
    let v_index = sim.v_index;
    let mut control = crate::checkpoint::Control::default();
    let outcome = sim.run(0.0, dt, steps, opts.progress, &mut control, &mut |_, _, _| {}, &mut |tools, step, _| {
        let v = v_index.map(|i| step.states[i].as_slice());
        let r = row(tools, &step.states[0], v, step.t);
        newton += step.report.iterations();
        if r.force > peak {
            peak = r.force;
            peak_state.clone_from(&step.states[0]);
        }
        series.push(r);
        Ok(())
    })?;
    if let Some(e) = outcome.stopped {
        // Its figures need the whole contact: keep what was computed for a look.
        if let Some(dir) = &opts.out {
            write_series(dir, &series)?;
        }
        return Err(e);
    }
    let end = series.last().map_or(0.0, |r| r.t);
    let duration = match contact_duration(&series) {
        Contact::Never => {
            return Err(CaseError::Option(format!("the ball never touched the plane by t = {end:.4}")));
        }
        Contact::Unfinished => {
            return Err(CaseError::Option(format!(
                "the ball is still in contact at t = {end:.4}: no rebound within 1.3 Hertz contact times"
            )));
        }
        Contact::Lasted(d) => d,
    };
    let pressure = sim.tools.contact_pressure.as_ref().expect("checked above");
    let samples = profile::sample(&asm, pressure.as_ref(), &peak_state);
    let peak_radius =
        profile::zone(3, meshes::copies(3), &samples, hertz.contact_radius).map_err(CaseError::Option)?.size;
    let measured = Figures { contact_duration: duration, peak_force: peak, contact_radius: peak_radius };
    let hertz_figures = Figures {
        contact_duration: hertz.contact_duration,
        peak_force: hertz.peak_force,
        contact_radius: hertz.contact_radius,
    };
    let rel = |a: f64, b: f64| a / b - 1.0;
    let summary = Summary {
        case: "hertz-impact",
        scheme: active.scheme_name().to_string(),
        contact: active.forms.contact_name().to_string(),
        params: active.forms.params.values(),
        radius,
        young: material.young,
        poisson: material.poisson,
        density: material.density,
        impact_velocity: opts.speed,
        mesh: mesh_name,
        cells: mesh.num_cells(),
        dofs: n,
        dt,
        steps,
        regime: Regime {
            indentation_ratio: hertz.max_indentation / radius,
            contact_time_over_wave_time: hertz.contact_duration * material.wave_speed() / radius,
        },
        relative_error: Figures {
            contact_duration: rel(measured.contact_duration, hertz.contact_duration),
            peak_force: rel(measured.peak_force, hertz.peak_force),
            contact_radius: rel(measured.contact_radius, hertz.contact_radius),
        },
        measured,
        hertz: hertz_figures,
        restitution: series.last().map_or(f64::NAN, |r| r.velocity) / opts.speed,
        newton_iterations: newton,
        wall_seconds: start.elapsed().as_secs_f64(),
    };
    if let Some(dir) = &opts.out {
        write(dir, &summary, &series, &material, gap0 / opts.speed)?;
    }
    Ok(Run { summary, series })
}

enum Contact {
    Never,
    Unfinished,
    Lasted(f64),
}

/// From the first step with an active contact point to the first after it with none: each end
/// is taken half a step before that step, and the two halves cancel.
fn contact_duration(series: &[Row]) -> Contact {
    let Some(first) = series.iter().position(|r| r.active_points > 0) else { return Contact::Never };
    let Some(length) = series[first..].iter().position(|r| r.active_points == 0) else { return Contact::Unfinished };
    Contact::Lasted(series[first + length].t - series[first].t)
}

fn write_series(dir: &std::path::Path, series: &[Row]) -> Result<(), CaseError> {
    let path = dir.join("series.csv");
    let mut csv = String::from("t,fz_contact,active_points,vz_mean,energy_aug\n");
    for r in series {
        csv.push_str(&format!("{:e},{:e},{},{:e},{:e}\n", r.t, r.force, r.active_points, r.velocity, r.energy_aug));
    }
    crate::output::write_atomic(&path, csv.as_bytes())
        .map_err(|source| CaseError::Write { path: path.display().to_string(), source })
}

fn write(
    dir: &std::path::Path,
    summary: &Summary,
    series: &[Row],
    material: &Material,
    t_hit: f64,
) -> Result<(), CaseError> {
    let err =
        |path: &std::path::Path, source: std::io::Error| CaseError::Write { path: path.display().to_string(), source };
    write_series(dir, series)?;
    let path = dir.join("summary.json");
    crate::output::write_json(&path, summary).map_err(|e| err(&path, e))?;
    use crate::plot::Curve;
    let hertz = Impact::force_history(summary.radius, material, summary.impact_velocity, summary.dt / 20.0)
        .into_iter()
        .map(|(t, f)| (t + t_hit, f))
        .collect();
    let path = dir.join("force.png");
    crate::plot::panels(
        &path,
        "t",
        &[(
            "contact force on the ball",
            "F",
            vec![
                Curve { label: "computed", points: series.iter().map(|r| (r.t, r.force)).collect(), dashed: false },
                Curve { label: "Hertz (quasi-static)", points: hertz, dashed: true },
            ],
        )],
    )
    .map_err(|e| err(&path, std::io::Error::other(e)))
}
