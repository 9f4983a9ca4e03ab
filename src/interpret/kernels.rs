//! `FormKernel` and `FunctionalKernel` for interpreted forms: the compiler's kernel plan
//! (`ir::plan`) run as the generated kernels run it, with the pointwise coefficients computed
//! by the IR evaluator and contracted with the basis functions by the plan's terms, in their
//! order.

use std::cell::Cell;

use signorini_compiler::ir::eval::CoefsAt;
use signorini_compiler::ir::plan::{Basis, Body, Contract, Decided, Integral, Leaf, Terms};
use signorini_runtime::fem::geometry;
use signorini_runtime::fem::kernel::{
    CellCtx, Coef, FacetCtx, FormKernel, FunctionalKernel, LocalMatrix, LocalVector, Tabulation,
};

/// The form's coefs at the time of a kernel call, for the points a body reads them at.
struct CoefsAtTime<'a> {
    coefs: &'a [Coef],
    t: f64,
}

impl CoefsAt for CoefsAtTime<'_> {
    fn at(&self, id: u16, comp: u8, dirs: &[u8], point: &[f64]) -> f64 {
        self.coefs.get(id as usize).map_or(f64::NAN, |c| c.at(point, self.t, comp as usize, dirs))
    }
}

use super::form::InterpretedForm;

/// Buffers reused across kernel calls, so that the loops allocate nothing.
#[derive(Default)]
struct Scratch {
    slots: Vec<f64>,
    coefs: Vec<f64>,
    /// The roots at the current point (weighted, except switches).
    roots: Vec<f64>,
}

thread_local! {
    // Taken for the duration of a call (a coef function may itself run a kernel).
    static SCRATCH: Cell<Scratch> = Cell::new(Scratch::default());
}

/// Where a kernel integrates: a cell, or a facet (its reference normal and the cell diameter).
struct Place<'a, const D: usize, const N: usize> {
    tab: &'a Tabulation<D, N>,
    coords: &'a [[f64; D]; N],
    facet: Option<(&'a [f64; D], f64)>,
    t: f64,
}

impl<'a, const D: usize, const N: usize> Place<'a, D, N> {
    fn cell(ctx: &CellCtx<'a, D, N>) -> Self {
        Place { tab: ctx.tab, coords: ctx.coords, facet: None, t: ctx.t }
    }

    fn facet(ctx: &FacetCtx<'a, D, N>) -> Self {
        Place { tab: ctx.tab, coords: ctx.coords, facet: Some((ctx.ref_normal, ctx.h)), t: ctx.t }
    }
}

impl InterpretedForm {
    /// Runs `body` at every quadrature point of `place`, calling `visit(phi, dphi, roots)`.
    fn each_point<const D: usize, const N: usize>(
        &self,
        body: &Body,
        place: &Place<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        mut visit: impl FnMut(&[f64; N], &[[f64; D]; N], &[f64]),
    ) {
        let mut s = SCRATCH.take();
        let Scratch { slots, coefs, roots } = &mut s;
        let prog = &body.prog;
        prog.prepare(slots);
        coefs.resize(body.coef_len, 0.0);
        roots.resize(prog.outputs(), 0.0);
        let h = place.facet.map_or(f64::NAN, |f| f.1);
        // The hoisted leaves, once per call; the others at each point.
        for (slot, leaf) in slots.iter_mut().zip(&body.leaves).filter(|(_, l)| l.hoisted()) {
            *slot = match *leaf {
                Leaf::Param(i) => self.params.get(i as usize).copied().unwrap_or(f64::NAN),
                Leaf::CellDiameter => h,
                Leaf::Time => place.t,
                // `Leaf::Zero`: the other leaves are not hoisted.
                _ => 0.0,
            };
        }
        let at = CoefsAtTime { coefs: &self.coefs, t: place.t };
        prog.exec_invariant_with(slots, &at);
        let weighted = body.weighted();
        let tab = place.tab;
        for q in 0..tab.len() {
            let phi = &tab.phi[q];
            let jac = geometry::jacobian(place.coords, &tab.dphi[q]);
            let (n, w) = match place.facet {
                Some((ref_normal, _)) => {
                    let (n, scale) = geometry::facet_normal(&jac, ref_normal);
                    (n, tab.weights[q] * scale)
                }
                None => ([0.0; D], tab.weights[q] * jac.det.abs()),
            };
            let dphi = if body.uses_dphi { geometry::physical_gradients(&jac, &tab.dphi[q]) } else { [[0.0; D]; N] };
            let x = if body.uses_x { geometry::interpolate(place.coords, phi) } else { [0.0; D] };
            for c in &body.coefs {
                self.coefs[c.id as usize].eval(&x, place.t, &mut coefs[c.at..c.at + c.len]);
            }
            for (slot, leaf) in slots.iter_mut().zip(&body.leaves).filter(|(_, l)| !l.hoisted()) {
                *slot = match *leaf {
                    // `geometry::interpolate` and `geometry::gradient`, one component each.
                    Leaf::Value { arg, comp } => fields.get(arg as usize).map_or(f64::NAN, |u| {
                        let mut v = 0.0;
                        for j in 0..N {
                            v += u[j][comp as usize] * phi[j];
                        }
                        v
                    }),
                    Leaf::Grad { arg, comp, dir } => fields.get(arg as usize).map_or(f64::NAN, |u| {
                        let mut v = 0.0;
                        for j in 0..N {
                            v += u[j][comp as usize] * dphi[j][dir as usize];
                        }
                        v
                    }),
                    Leaf::Normal(k) => n[k as usize],
                    Leaf::Coord(k) => x[k as usize],
                    Leaf::Coef { at, .. } => coefs[at as usize],
                    // Hoisted: set once above.
                    Leaf::Param(_) | Leaf::CellDiameter | Leaf::Time | Leaf::Zero => continue,
                };
            }
            prog.exec_varying_with(slots, &at);
            for (i, r) in roots.iter_mut().enumerate() {
                let v = prog.root(slots, i);
                *r = if weighted { w * v } else { v };
            }
            visit(phi, &dphi, roots);
        }
        SCRATCH.set(s);
    }

    fn residual<const D: usize, const N: usize>(
        &self,
        body: &Body,
        place: &Place<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        out: &mut LocalVector<D, N>,
    ) {
        let Contract::Residual { rows } = &body.contract else { return };
        self.each_point(body, place, fields, |phi, dphi, r| {
            for j in 0..N {
                for (k, terms) in rows.iter().enumerate() {
                    if let Some(v) = sum(terms, r, phi[j], &dphi[j]) {
                        out[j][k] += v;
                    }
                }
            }
        });
    }

    fn tangent<const D: usize, const N: usize>(
        &self,
        body: &Body,
        place: &Place<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        out: &mut LocalMatrix<D, N>,
    ) {
        let Contract::Tangent { a, b } = &body.contract else { return };
        // a[k][m] and b[k][m][n] at one test node (absent terms are `None`, as the generated
        // code omits them).
        let mut av = [None; 9];
        let mut bv = [None; 27];
        self.each_point(body, place, fields, |phi, dphi, r| {
            for i in 0..N {
                for (v, terms) in av.iter_mut().zip(a) {
                    *v = sum(terms, r, phi[i], &dphi[i]);
                }
                for (v, terms) in bv.iter_mut().zip(b) {
                    *v = sum(terms, r, phi[i], &dphi[i]);
                }
                for j in 0..N {
                    for k in 0..D {
                        for m in 0..D {
                            let mut acc = av[k * D + m].map(|a| a * phi[j]);
                            for n in 0..D {
                                if let Some(b) = bv[(k * D + m) * D + n] {
                                    let t = b * dphi[j][n];
                                    acc = Some(acc.map_or(t, |s| s + t));
                                }
                            }
                            if let Some(v) = acc {
                                out[i][k][j][m] += v;
                            }
                        }
                    }
                }
            }
        });
    }

    /// Pushes the switches of `integral`'s tangent with respect to `wrt`; whether they decide
    /// it at these points (as generated kernels do).
    fn switches<const D: usize, const N: usize>(
        &self,
        integral: Option<&Integral>,
        wrt: usize,
        place: &Place<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        out: &mut Vec<bool>,
    ) -> bool {
        let Some(integral) = integral else { return true };
        let decided = integral.decided.get(wrt).unwrap_or(&Decided::Always);
        let mut gated = !matches!(decided, Decided::Never);
        if let Some(body) = integral.switches.get(wrt).and_then(Option::as_ref) {
            let Contract::Switches { count } = body.contract else { return gated };
            self.each_point(body, place, fields, |_, _, r| {
                let (set, gates) = r.split_at(count);
                out.extend(set.iter().map(|&v| v > 0.0));
                gated &= gates.iter().all(|&v| v <= 0.0);
            });
        }
        gated
    }

    fn value<const D: usize, const N: usize>(
        &self,
        body: Option<&Body>,
        place: &Place<'_, D, N>,
        fields: &[&LocalVector<D, N>],
    ) -> f64 {
        let mut total = 0.0;
        if let Some(body) = body {
            self.each_point(body, place, fields, |_, _, r| total += r[0]);
        }
        total
    }

    fn cell_integral<const D: usize>(&self) -> Option<&Integral> {
        self.kernels::<D>().cell.as_ref()
    }

    fn facet_integral<const D: usize>(&self, region: usize) -> Option<&Integral> {
        self.kernels::<D>().facets.get(region)
    }
}

/// `Σ basis·root` over `terms`, left to right; `None` if there are none.
#[inline]
fn sum<const D: usize>(terms: &Terms, roots: &[f64], phi: f64, dphi: &[f64; D]) -> Option<f64> {
    let term = |&(basis, r): &(Basis, u32)| {
        let c = roots[r as usize];
        match basis {
            Basis::Phi => c * phi,
            Basis::Dphi(l) => c * dphi[l as usize],
        }
    };
    let mut it = terms.iter();
    let first = term(it.next()?);
    Some(it.fold(first, |s, t| s + term(t)))
}

impl<const D: usize, const N: usize> FormKernel<D, N> for InterpretedForm {
    fn cell_residual(&self, ctx: &CellCtx<'_, D, N>, fields: &[&LocalVector<D, N>], out: &mut LocalVector<D, N>) {
        if let Some(body) = self.cell_integral::<D>().and_then(|i| i.residual.as_ref()) {
            self.residual(body, &Place::cell(ctx), fields, out);
        }
    }

    fn cell_tangent(
        &self,
        ctx: &CellCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        wrt: usize,
        out: &mut LocalMatrix<D, N>,
    ) {
        if let Some(body) = self.cell_integral::<D>().and_then(|i| i.tangents.get(wrt)?.as_ref()) {
            self.tangent(body, &Place::cell(ctx), fields, out);
        }
    }

    fn cell_switches(
        &self,
        ctx: &CellCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        wrt: usize,
        out: &mut Vec<bool>,
    ) -> bool {
        self.switches(self.cell_integral::<D>(), wrt, &Place::cell(ctx), fields, out)
    }

    fn facet_residual(
        &self,
        region: usize,
        ctx: &FacetCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        out: &mut LocalVector<D, N>,
    ) {
        if let Some(body) = self.facet_integral::<D>(region).and_then(|i| i.residual.as_ref()) {
            self.residual(body, &Place::facet(ctx), fields, out);
        }
    }

    fn facet_tangent(
        &self,
        region: usize,
        ctx: &FacetCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        wrt: usize,
        out: &mut LocalMatrix<D, N>,
    ) {
        if let Some(body) = self.facet_integral::<D>(region).and_then(|i| i.tangents.get(wrt)?.as_ref()) {
            self.tangent(body, &Place::facet(ctx), fields, out);
        }
    }

    fn facet_switches(
        &self,
        region: usize,
        ctx: &FacetCtx<'_, D, N>,
        fields: &[&LocalVector<D, N>],
        wrt: usize,
        out: &mut Vec<bool>,
    ) -> bool {
        self.switches(self.facet_integral::<D>(region), wrt, &Place::facet(ctx), fields, out)
    }
}

impl<const D: usize, const N: usize> FunctionalKernel<D, N> for InterpretedForm {
    fn cell_value(&self, ctx: &CellCtx<'_, D, N>, fields: &[&LocalVector<D, N>]) -> f64 {
        let body = self.cell_integral::<D>().and_then(|i| i.value.as_ref());
        self.value(body, &Place::cell(ctx), fields)
    }

    fn facet_value(&self, region: usize, ctx: &FacetCtx<'_, D, N>, fields: &[&LocalVector<D, N>]) -> f64 {
        let body = self.facet_integral::<D>(region).and_then(|i| i.value.as_ref());
        self.value(body, &Place::facet(ctx), fields)
    }
}
