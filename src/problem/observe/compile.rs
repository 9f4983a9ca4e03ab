//! The compile of a column: its expression with every measured value (a reducer, a
//! functional, a row value) replaced by a placeholder the column's program reads, and the
//! measures added to the observer; and why a column cannot be measured on a run.

use super::*;
use crate::compiler::Diagnostic;
use crate::compiler::Span;

impl<'m> Observer<'m> {
    /// Why a column's expression cannot be measured on this run, if it cannot: a functional of
    /// the library's laws (not a misspelt name) that neither the files in use nor the reference
    /// provide, or a column left out.
    pub(super) fn unavailable(&self, e: &Expr, inst: &crate::driver::Instance<'m>) -> Option<String> {
        let state = |a: &Expr| {
            matches!(&a.kind, ExprKind::Name(n)
                if crate::compiler::check::problem::FUNCTIONAL_STATES.iter().any(|(s, _)| *s == n.name))
        };
        match &e.kind {
            ExprKind::Name(id) => {
                self.left_out.iter().any(|(c, _)| *c == id.name).then(|| format!("it reads `{}`, left out", id.name))
            }
            ExprKind::Call(f, args) if !args.is_empty() && args.iter().all(state) => {
                let by_files = self.functionals.iter().any(|(n, _)| *n == f.name) || inst.provides_functional(&f.name);
                let by_reference =
                    self.reference.as_ref().is_some_and(|(r, _)| r.functionals().iter().any(|(n, _)| *n == f.name));
                let known = crate::driver::library_functional(&f.name);
                (known && !by_files && !by_reference).then(|| format!("no file in use provides `{}`", f.name))
            }
            ExprKind::Call(_, args) | ExprKind::Vector(args) => args.iter().find_map(|a| self.unavailable(a, inst)),
            ExprKind::Neg(a) => self.unavailable(a, inst),
            ExprKind::Binary(_, a, b) | ExprKind::Index(a, b) => {
                self.unavailable(a, inst).or_else(|| self.unavailable(b, inst))
            }
            ExprKind::Number(_) => None,
        }
    }

    /// `e` with every measured value replaced by a placeholder name; the measures are added,
    /// and their (id, components) to `leaves`.
    pub(super) fn rewrite(
        &mut self,
        c: &mut Compiling<'_, '_, 'm>,
        e: &Expr,
        leaves: &mut Vec<(usize, usize)>,
    ) -> Result<Expr, CaseError> {
        let mut again = |o: &mut Self, a: &Expr| o.rewrite(c, a, leaves).map(Box::new);
        Ok(match &e.kind {
            ExprKind::Number(_) => e.clone(),
            ExprKind::Name(id) => match self.row_value(&id.name) {
                Some(m) => self.add(leaves, m, 1, e.span),
                None => e.clone(), // a param or a let
            },
            ExprKind::Neg(a) => Expr { kind: ExprKind::Neg(again(self, a)?), span: e.span },
            ExprKind::Binary(op, a, b) => {
                let a = again(self, a)?;
                Expr { kind: ExprKind::Binary(*op, a, again(self, b)?), span: e.span }
            }
            ExprKind::Index(a, k) => Expr { kind: ExprKind::Index(again(self, a)?, k.clone()), span: e.span },
            ExprKind::Vector(_) => unreachable!("checked: no vector in a column"),
            ExprKind::Call(f, args) => match crate::compiler::check::problem::row_reducer(&f.name).map(|r| r.kind) {
                None if crate::compiler::check::problem::row_function(&f.name).is_some() => {
                    let args = args.iter().map(|a| self.rewrite(c, a, leaves)).collect::<Result<Vec<_>, _>>()?;
                    Expr { kind: ExprKind::Call(f.clone(), args), span: e.span }
                }
                Some(kind) => {
                    let (m, comps) = self.reducer(c, kind, args)?;
                    self.add(leaves, m, comps, e.span)
                }
                None => {
                    let m = self.functional(c, f, args, e.span)?;
                    self.add(leaves, m, 1, e.span)
                }
            },
        })
    }

    /// Adds a measure; its placeholder in the rewritten expression.
    fn add(&mut self, leaves: &mut Vec<(usize, usize)>, m: Measure, comps: usize, span: Span) -> Expr {
        self.measures.push(m);
        let id = self.measures.len() - 1;
        leaves.push((id, comps));
        Expr { kind: ExprKind::Name(Ident { name: placeholder(id), span }), span }
    }

    /// A name a row measures: an earlier column first (`series energy = energy` is then read,
    /// not measured again, by the columns after it), or a value of the row's state.
    fn row_value(&self, name: &str) -> Option<Measure> {
        let column = self.columns.iter().position(|(n, _, _)| *n == name).map(Measure::Column);
        column.or(match name {
            "t" => Some(Measure::Time),
            "energy" => Some(Measure::Energy),
            "kinetic" => Some(Measure::Kinetic),
            "newton" => Some(Measure::Newton),
            "active_points" => Some(Measure::ActivePoints),
            "status_kept" => Some(Measure::StatusKept),
            _ => None,
        })
    }

    /// The measure of a reducer's call, and its number of components.
    fn reducer(
        &mut self,
        c: &mut Compiling<'_, '_, 'm>,
        kind: R,
        args: &[Expr],
    ) -> Result<(Measure, usize), CaseError> {
        let d = c.ops.asm.mesh().dim();
        Ok(match kind {
            R::Mean | R::NodalMean | R::AtMin => (pointwise_reducer(c, kind, args)?, 1),
            R::Force | R::Work => {
                let ExprKind::Name(slot) = &args[0].kind else { unreachable!("checked: a slot name") };
                let slot = self.slot(c, slot)?;
                match kind {
                    R::Work => (Measure::Work { slot }, 1),
                    _ => (Measure::Force { slot, dofs: region_dofs(c, args.get(1))? }, d),
                }
            }
            R::Cumulative | R::Initial => {
                let ExprKind::Name(id) = &args[0].kind else { unreachable!("checked: a column's name") };
                let column = self.columns.iter().position(|(n, _, _)| *n == id.name).ok_or_else(|| {
                    c.pf.render(Diagnostic::error(
                        "E0101",
                        format!("no earlier column `{}` on this run", id.name),
                        id.span,
                        "not measured",
                    ))
                })?;
                let sum = kind == R::Cumulative;
                let value = std::cell::Cell::new(if sum { 0.0 } else { f64::NAN });
                (Measure::OverRows { column, sum, value }, 1)
            }
            R::InnerMass => (Measure::InnerMass { a: c.pointwise(&args[0])?, b: c.pointwise(&args[1])? }, 1),
            R::DensityMin | R::DensityMax | R::DensitySupport => {
                let ExprKind::Call(name, _) = &args[0].kind else { unreachable!("checked: a functional") };
                let index = self.facet_functional(c, name)?;
                let of = match kind {
                    R::DensityMin => Density::Min,
                    R::DensityMax => Density::Max,
                    _ => Density::Support,
                };
                (Measure::Density { index, of }, 1)
            }
            R::Measure | R::Peak => {
                let ExprKind::Name(region) = &args[0].kind else { unreachable!("checked: a region name") };
                let region = self.region(c, region)?;
                let f = c.pointwise(&args[1])?;
                let m = if kind == R::Measure { Measure::Area { region, f } } else { Measure::Peak { region, f } };
                (m, 1)
            }
        })
    }

    /// The index of a slot's form among those the measures read, taken from the files in use
    /// at its first read.
    fn slot(&mut self, c: &mut Compiling<'_, '_, 'm>, slot: &Ident) -> Result<usize, CaseError> {
        if let Some(i) = self.slots.iter().position(|(n, _)| *n == slot.name) {
            return Ok(i);
        }
        let form = c.inst.take_form(&slot.name).ok_or_else(|| {
            c.pf.render(Diagnostic::error(
                "E0101",
                format!("no form of the files in use provides slot `{}`", slot.name),
                slot.span,
                "not provided",
            ))
        })?;
        self.slots.push((slot.name.clone(), form));
        Ok(self.slots.len() - 1)
    }

    /// The index of a region among those `measure` and `peak` sample.
    fn region(&mut self, c: &mut Compiling<'_, '_, 'm>, region: &Ident) -> Result<usize, CaseError> {
        let facets = c
            .binding
            .regions
            .iter()
            .find(|(n, _)| *n == region.name)
            .map(|(_, f)| *f)
            .ok_or_else(|| CaseError::Option(format!("region `{}` is not bound", region.name)))?;
        if let Some(i) = c.region_names.iter().position(|n| *n == region.name) {
            return Ok(i);
        }
        c.region_names.push(region.name.clone());
        self.regions.push(facets);
        Ok(self.regions.len() - 1)
    }

    /// The index of a functional over boundary facets, for `density_min`, `density_max` and
    /// `density_support`
    /// (a cell functional has no facet to sample).
    fn facet_functional(&mut self, c: &mut Compiling<'_, '_, 'm>, name: &Ident) -> Result<usize, CaseError> {
        let index = match self.functionals.iter().position(|(n, _)| *n == name.name) {
            Some(i) => i,
            None => {
                let func = c.inst.take_functional(&name.name).ok_or_else(|| {
                    c.pf.render(Diagnostic::error(
                        "E0101",
                        format!("no functional `{}` in the files in use", name.name),
                        name.span,
                        "not provided",
                    ))
                })?;
                self.functionals.push((name.name.clone(), func));
                self.functionals.len() - 1
            }
        };
        let d = c.ops.asm.mesh().dim();
        let rule = crate::runtime::fem::quadrature::sampling_rule(d - 1, 1);
        let zero = vec![0.0; c.ops.asm.size()];
        if self.functionals[index].1.facet_point_values(c.ops.asm, &rule, &[&zero], 0.0).is_empty() {
            return Err(c.pf.render(
                Diagnostic::error(
                    "E0301",
                    format!("`{}` integrates over no boundary facet", name.name),
                    name.span,
                    "no facet to sample",
                )
                .with_help(
                    "density_min, density_max and density_support read a functional over a boundary region: `int(Gamma_C) ...`",
                ),
            ));
        }
        Ok(index)
    }

    /// A functional of the files in use, or else of the reference, at the states its
    /// arguments name.
    fn functional(
        &mut self,
        c: &mut Compiling<'_, '_, 'm>,
        f: &Ident,
        args: &[Expr],
        span: Span,
    ) -> Result<Measure, CaseError> {
        let name = f.name.as_str();
        let at: Vec<Level> = args
            .iter()
            .map(|a| match &a.kind {
                ExprKind::Name(n) if n.name == "u_mid" => Level::Mid,
                ExprKind::Name(n) if n.name == "u_prev" => Level::Start,
                _ => Level::Now,
            })
            .collect();
        let known = self.functionals.iter().position(|(n, _)| n == name);
        let index = known.or_else(|| {
            let f = c.inst.take_functional(name)?;
            self.functionals.push((name.to_string(), f));
            Some(self.functionals.len() - 1)
        });
        let Some(index) = index else { return self.reference_functional(c, f, at.contains(&Level::Mid)) };
        let fields = self.functionals[index].1.fields();
        if fields != at.len() {
            let help = match fields {
                2 => format!("write `{name}(u, u_prev)`: the step's end and start"),
                _ => format!("write `{name}(u)`"),
            };
            let d = Diagnostic::error(
                "E0201",
                format!("`{name}` takes {fields} state(s)"),
                span,
                format!("{} given", at.len()),
            );
            return Err(c.pf.render(d.with_help(help)));
        }
        Ok(Measure::Functional { index, at })
    }

    /// A functional of the problem's reference, when no file in use provides it.
    fn reference_functional(&self, c: &Compiling<'_, '_, 'm>, f: &Ident, mid: bool) -> Result<Measure, CaseError> {
        let name = f.name.as_str();
        let names: Vec<&str> = self.reference.iter().flat_map(|(r, _)| r.functionals()).map(|(n, _)| n).collect();
        if let Some(which) = names.iter().position(|n| *n == name) {
            return Ok(Measure::Reference { which, mid });
        }
        let mut d =
            Diagnostic::error("E0101", format!("no functional `{name}` in the files in use"), f.span, "not provided");
        match &self.reference {
            Some((r, _)) => {
                d = d.with_note(format!("nor in reference `{}`: {}", r.name(), names.join(", ")));
                if let Some(s) = crate::compiler::check::suggest_name(name, names.iter().copied()) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
            }
            None => d = d.with_note("the problem names no reference (`reference NAME`)"),
        }
        Err(c.pf.render(d))
    }
}

/// What compiling the columns shares: the problem file, its expressions, the operators, the
/// files in use (their forms and functionals taken as the measures read them), the pointwise
/// values (`u`, `v`, the coefs) and the regions bound and sampled so far.
pub(super) struct Compiling<'c, 'u, 'm> {
    pub pf: &'c ProblemFile,
    pub ex: &'c mut Exprs<'u>,
    pub ops: &'c Operators<'m>,
    pub inst: crate::driver::Instance<'m>,
    pub pointwise: Vec<(String, Val)>,
    pub binding: &'c Binding<'m>,
    pub region_names: Vec<String>,
}

impl Compiling<'_, '_, '_> {
    /// An expression of the point's values (`u`, `v`, `x`, `t`, the coefs) as a function.
    fn pointwise(&mut self, e: &Expr) -> Result<PointFn, CaseError> {
        let val = self.ex.lower(e, &self.pointwise).map_err(|d| self.pf.render(*d))?;
        self.ex.function(&val, e).map_err(|d| self.pf.render(*d))
    }
}

/// `mean(u[k])`, `nodal_mean(u[k])` (over a body: `mean(u[k], BODY)`) and `at_min(u[k], KEY)`.
fn pointwise_reducer(c: &mut Compiling, kind: R, args: &[Expr]) -> Result<Measure, CaseError> {
    let d = c.ops.asm.mesh().dim();
    let ExprKind::Index(f, k) = &args[0].kind else { unreachable!("checked: u[k] or v[k]") };
    let field = matches!(&f.kind, ExprKind::Name(n) if n.name == "v") as u8;
    let axis = crate::compiler::check::const_value(k).unwrap_or(0.0) as usize;
    if axis >= d {
        let why = format!("component {axis} of a field in a {d}D problem");
        return Err(c.pf.render(Diagnostic::error("E0302", "wrong dimension", args[0].span, why)));
    }
    // A body's name, checked: the mesh has its nodes.
    let nodes = match args.get(1).map(|a| &a.kind) {
        Some(ExprKind::Name(body)) if kind != R::AtMin => c.ops.asm.mesh().body_nodes(&body.name),
        _ => None,
    };
    Ok(match kind {
        R::Mean => Measure::Mean { field, weights: c.ops.axis_mean(axis, nodes.as_deref()) },
        R::NodalMean => Measure::NodalMean { field, axis, nodes },
        _ => {
            let val = c.ex.lower(&args[1], &[]).map_err(|e| c.pf.render(*e))?;
            let key = c.ex.function(&val, &args[1]).map_err(|e| c.pf.render(*e))?;
            let mesh = c.ops.asm.mesh();
            let (mut scratch, mut out) = (Vec::new(), [0.0]);
            let mut at = |i: usize| {
                key.eval(&At { x: mesh.node(i), ..At::default() }, &mut scratch, &mut out);
                out[0]
            };
            let values: Vec<f64> = (0..mesh.num_nodes()).map(&mut at).collect();
            let node = (0..mesh.num_nodes())
                .min_by(|&a, &b| values[a].total_cmp(&values[b]))
                .ok_or_else(|| CaseError::Option("the mesh has no node".into()))?;
            let massless = c.ops.redistributed && c.ops.contact_nodes.contains(&(node as u32));
            Measure::AtMin { field, axis, node, massless }
        }
    })
}

/// `force(SLOT, REGION)`'s dofs: those of the region's nodes, component by component (all
/// without a region).
fn region_dofs(c: &Compiling, region: Option<&Expr>) -> Result<Option<Vec<usize>>, CaseError> {
    let Some(ExprKind::Name(region)) = region.map(|a| &a.kind) else { return Ok(None) };
    let mesh = c.ops.asm.mesh();
    let d = mesh.dim();
    // A body's nodes, else a region's.
    let nodes: Vec<u32> = match mesh.body_nodes(&region.name) {
        Some(of) => (0..of.len() as u32).filter(|&n| of[n as usize]).collect(),
        None => mesh.region_nodes(mesh.region(&region.name)?),
    };
    Ok(Some(nodes.iter().flat_map(|&n| (0..d).map(move |k| n as usize * d + k)).collect()))
}
