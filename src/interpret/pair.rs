//! `PairKernel` for interpreted forms: a pair law's pointwise programs (`ir::pair`) run with
//! their leaves read on the two sides of a pair point.

use std::cell::Cell;

use signorini_compiler::ir::eval::{CoefsAt, Program};
use signorini_compiler::ir::graph::Sym;
use signorini_runtime::fem::pair::{PairKernel, PairPoint, SideAt};

use super::form::InterpretedForm;

thread_local! {
    // Taken for the duration of a call, so that the points allocate nothing.
    static SLOTS: Cell<Vec<f64>> = const { Cell::new(Vec::new()) };
}

/// The form's coefs at the time of a pair point.
struct CoefsAtTime<'a> {
    form: &'a InterpretedForm,
    t: f64,
}

impl CoefsAt for CoefsAtTime<'_> {
    fn at(&self, id: u16, comp: u8, dirs: &[u8], point: &[f64]) -> f64 {
        self.form.coefs.get(id as usize).map_or(f64::NAN, |c| c.at(point, self.t, comp as usize, dirs))
    }
}

impl InterpretedForm {
    /// The value of leaf `s` on `side` (the own one, or the facing one for `opposite`).
    fn pair_leaf(&self, s: Sym, p: &PairPoint) -> f64 {
        let read = |side: &SideAt, s: Sym| match s {
            Sym::Field { arg, comp } => side.fields.get(arg as usize).map_or(f64::NAN, |u| u.value[comp as usize]),
            Sym::FieldGrad { arg, comp, dir } => {
                side.fields.get(arg as usize).map_or(f64::NAN, |u| u.grad[comp as usize][dir as usize])
            }
            Sym::Normal(k) => side.normal[k as usize],
            Sym::Coord(k) => side.x[k as usize],
            Sym::CellDiameter => side.h,
            Sym::FieldHess { arg, comp, dir, along } => {
                side.fields.get(arg as usize).map_or(f64::NAN, |u| u.hess[comp as usize][dir as usize][along as usize])
            }
            Sym::NormalRate { comp, along } => side.normal_rate[comp as usize][along as usize],
            Sym::Coef { id, comp } => {
                self.coefs.get(id as usize).map_or(f64::NAN, |c| c.at(&side.x[..p.dim], p.t, comp as usize, &[]))
            }
            _ => 0.0,
        };
        match s {
            Sym::Param(i) => self.params.get(i as usize).copied().unwrap_or(f64::NAN),
            Sym::Time => p.t,
            Sym::Opposite(f) => read(&p.facing, f.own()),
            // The test functions' coefficients are the roots; a seed is 0 once lowered.
            Sym::Test { .. } | Sym::TestGrad { .. } | Sym::Dt | Sym::Seed(_) => 0.0,
            s => read(&p.own, s),
        }
    }

    /// Runs `prog` at `p` into `out` (one entry per root).
    fn run_pair(&self, prog: &Program, p: &PairPoint, out: &mut [f64]) {
        let mut slots = SLOTS.take();
        prog.prepare(&mut slots);
        for (slot, &s) in slots.iter_mut().zip(prog.syms()) {
            *slot = self.pair_leaf(s, p);
        }
        let at = CoefsAtTime { form: self, t: p.t };
        prog.exec_invariant_with(&mut slots, &at);
        prog.exec_varying_with(&mut slots, &at);
        for (i, o) in out.iter_mut().enumerate().take(prog.outputs()) {
            *o = prog.root(&slots, i);
        }
        SLOTS.set(slots);
    }
}

impl PairKernel for InterpretedForm {
    fn both_sides(&self) -> bool {
        self.over_both_sides()
    }

    fn residual_at(&self, region: usize, p: &PairPoint, out: &mut [f64]) -> bool {
        let Some(prog) = self.pair_integrals().and_then(|i| i.get(region)).and_then(|i| i.residual.as_ref()) else {
            return false;
        };
        self.run_pair(prog, p, out);
        true
    }

    fn tangent_at(&self, region: usize, p: &PairPoint, wrt: usize, out: &mut [f64]) -> bool {
        let Some(prog) = self.pair_integrals().and_then(|i| i.get(region)).and_then(|i| i.tangents.get(wrt)) else {
            return false;
        };
        self.run_pair(prog, p, out);
        true
    }

    fn value_at(&self, region: usize, p: &PairPoint) -> f64 {
        let Some(prog) = self.pair_integrals().and_then(|i| i.get(region)).and_then(|i| i.value.as_ref()) else {
            return 0.0;
        };
        let mut out = [0.0];
        self.run_pair(prog, p, &mut out);
        out[0]
    }
}
