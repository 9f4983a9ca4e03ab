//! A run's summary.json keys: what ran (the problem, files, params, mesh, times), the problem's
//! own keys and expectations, what it cost (Newton, factorizations, time, memory), and notes on
//! what is undefined or left out.

use super::{Ran, Request, Runner};
use crate::problem::outputs::{Summary, all_params, json};
use crate::problem::run::Observing;

type Put<'s> = dyn FnMut(&str, serde_json::Value) + 's;

pub(super) fn summary(req: &Request, ran: &Ran, observing: &Observing) -> Summary {
    let mut summary = Summary::default();
    let mut put = |k: &str, v: serde_json::Value| summary.keys.push((k.to_string(), v));
    what_ran(req, ran, &mut put);
    let series = &ran.stepped.rows.series;
    let (own, expectations) = observing.keys.values(series);
    for (k, v) in &own {
        put(k, json(v));
    }
    if !expectations.is_empty() {
        put("expected", json(&expectations));
    }
    cost(req, ran, &mut put);
    let notes = notes(req, &own, observing);
    if !notes.is_empty() {
        put("notes", json(&notes));
    }
    summary.own = own.into_iter().map(|(k, _)| k).collect();
    summary
}

/// The problem, the files and params in use, the mesh and the times.
fn what_ran(req: &Request, ran: &Ran, put: &mut Put) {
    let (pf, in_use, opts) = (req.pf, req.in_use, req.opts);
    let statics = matches!(ran.runner, Runner::Static(_));
    put("case", pf.name().into());
    put("problem", pf.file.clone().into());
    put("scheme", if statics { "static".into() } else { in_use.scheme_name().into() });
    put("contact", in_use.forms.contact_name().into());
    put("interpreted", json(&in_use.interpreted()));
    put("compiled_for_material", json(&in_use.rebound()));
    put("params", json(&all_params(in_use, req.params, pf)));
    put("mass", json(&opts.mass));
    put("cell_size", json(&opts.cell_size));
    put("mesh", ran.sized.mesh.clone().into());
    put("cells", ran.sized.cells.into());
    put("dofs", ran.sized.dofs.into());
    put("dt", json(&req.times.dt));
    put("steps", ran.stepped.steps.into());
    // The time reached (t_end, or where the run stopped).
    put("t_end", json(&ran.stepped.rows.series.last().map_or(req.times.t_start, |r| r.0)));
}

/// What the run cost, and how it ended.
fn cost(req: &Request, ran: &Ran, put: &mut Put) {
    let (outcome, counters) = (&ran.stepped.outcome, &ran.stepped.counters);
    let iterations = &ran.stepped.rows.iterations;
    let steps = ran.stepped.steps;
    put("newton_total", iterations.iter().sum::<usize>().into());
    put("newton_max", iterations.iter().max().copied().unwrap_or(0).into());
    put("wall_seconds", json(&ran.wall));
    put("seconds_per_step", json(&(ran.wall / steps.max(1) as f64)));
    put("stepping_seconds", json(&outcome.step_seconds.iter().sum::<f64>()));
    put("step_median_seconds", json(&crate::resources::median(outcome.step_seconds.clone())));
    put("factorizations", counters.numeric.into());
    put("symbolic_factorizations", counters.symbolic.into());
    put("low_rank_updates", counters.updates.into());
    put("matrix_nnz", ran.sized.matrix_nnz.into());
    let sim = match ran.runner {
        Runner::Time(sim) => Some(sim),
        Runner::Static(_) => None,
    };
    put("factor_nnz", json(&sim.and_then(|s| s.stepper.factor_nnz())));
    // The contact pairs' search and assembly by the scheme's forms (the steps, the initial
    // acceleration and the start's probes) or a static run's contact form (its solve); the
    // observers' functionals aside; and their share of the run's time.
    if let Some(c) = Some(ran.stepped.search).filter(|c| c.builds > 0) {
        put(
            "pair_search",
            serde_json::json!({
                "builds": c.builds,
                "queries": c.queries,
                "search_seconds": c.search_seconds,
                "assembly_seconds": c.assembly_seconds,
                "share_of_run": c.assembly_seconds / ran.wall,
            }),
        );
    }
    // An explicit scheme's critical step, estimated at the start (docs/language.md).
    if let Some(stable) = sim.and_then(|s| s.stable) {
        put("stable_dt", json(&stable.dt));
        put("omega_max", json(&stable.omega_max));
        // Along a run whose stiffness is nonlinear: the smallest estimate from the current tangent.
        if let Some((least, at)) = sim.and_then(|s| s.tracker.as_ref()).and_then(|t| t.least) {
            put("stable_dt_least", json(&least));
            put("stable_dt_least_at", json(&at));
        }
    }
    put("solver", json(&req.opts.newton.solver));
    put("krylov_iterations", counters.iterations.into());
    put("linear_solves", counters.solves.into());
    put("peak_memory_bytes", json(&crate::resources::peak_memory()));
    put("step_cuts", outcome.cuts.into());
    // An adaptive run's steps: accepted, taken again (for their error, to land on an event,
    // after a failed Newton), the events landed on, and the step sizes' range.
    if let (Some(steps), Some(asked)) = (&outcome.adaptive, &req.times.adaptive) {
        put(
            "adaptive",
            serde_json::json!({
                "tolerance": asked.tolerance,
                "accepted": steps.accepted,
                "rejected": steps.rejected(),
                "rejected_for_error": steps.rejected_error,
                "rejected_for_event": steps.rejected_event,
                "failed": steps.failed,
                "events": steps.events,
                "dt_min": steps.dt_min,
                "dt_max": steps.dt_max,
            }),
        );
    }
    // A run without inertia (static, or a scheme without `mass`) watches no energy.
    if sim.is_some_and(|s| s.inertia) {
        put("energy_growth", json(&outcome.energy_growth));
    }
    if let Some(stopped) = &outcome.stopped {
        put("stopped", stopped.to_string().into());
    }
    if let Some(resumed) = &outcome.resumed {
        put("resumed", json(resumed));
    }
}

/// Why a key is null: undefined on this run (0/0 or no row where `first` finds one); and what
/// this run left out.
fn notes(req: &Request, own: &[(String, Option<f64>)], observing: &Observing) -> Vec<String> {
    let pf = req.pf;
    let mut notes: Vec<String> = own
        .iter()
        .filter(|(_, v)| !v.is_some_and(f64::is_finite))
        .map(|(k, _)| {
            let at = pf.problem().summary.iter().find(|d| d.name.name == *k).map(|d| d.span);
            let line = at.map_or(0, |s| pf.program.unit.sources.line_col(s.file, s.start).0);
            format!("{k} is undefined on this run (its expression at {}:{line} has no value)", pf.file)
        })
        .collect();
    for (name, why) in observing.observer.left_out.iter().chain(&observing.keys.left_out) {
        notes.push(format!("{name} is left out of this run: {why}"));
    }
    notes
}
