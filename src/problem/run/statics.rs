//! A static problem's run: one equilibrium by the static driver, whose single row is the
//! solution.

use std::time::Instant;

use super::{Bound, Request, Rows, Stepped, row};
use crate::error::CaseError;
use crate::problem::observe::{Observer, State};
use crate::runtime::fem::assembly::Assembler;
use crate::simulation::{Operators, Outcome, Snapshots};

pub(super) fn run(
    req: &Request,
    ops: &Operators,
    asm: &Assembler,
    bound: &Bound,
    observer: &Observer,
    snapshots: &mut Snapshots,
    u0: Vec<f64>,
) -> Result<Stepped, CaseError> {
    let t0 = req.times.t_start;
    let clock = Instant::now();
    // The level a law's `prev` reads: the state the equilibrium is sought from.
    let initial = u0.clone();
    let mut problem = bound.statics(bound.contact, req.opts, t0);
    // The held dofs keep the values the initial fields took from the Dirichlet conditions.
    for dof in problem.constraints.dofs() {
        problem.constraints.values[dof] = u0[dof];
    }
    let solution = crate::simulation::statics::solve(asm, problem, &req.in_use.forms, u0)?;
    let seconds = clock.elapsed().as_secs_f64();
    let newton = solution.newton.iterations();
    let state = State { newton, ..State::new(t0, &solution.u, &initial) };
    let (first, switches) = row(observer, ops, state);
    snapshots.write(ops, 0, t0, &solution.u, &vec![0.0; asm.size()])?;
    let outcome = Outcome {
        step_seconds: vec![seconds],
        cuts: 0,
        stopped: None,
        resumed: None,
        energy_growth: 0.0,
        adaptive: None,
    };
    let rows = Rows { series: vec![first], switches: vec![switches], iterations: vec![newton], ..Rows::default() };
    Ok(Stepped {
        rows,
        outcome,
        counters: solution.counters,
        steps: 0,
        last: (t0, solution.u, None),
        search: solution.search,
    })
}
