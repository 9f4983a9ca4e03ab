//! The compile of a column: its expression with every measured value (a reducer, a
//! functional, a row value) replaced by a placeholder the column's program reads, and the
//! measures added to the observer; and why a column cannot be measured on a run.

use super::*;

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

    /// `e` with every measured value replaced by a placeholder name; the measures are added.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn rewrite(
        &mut self,
        pf: &ProblemFile,
        ex: &mut Exprs,
        ops: &Operators<'m>,
        inst: &mut crate::driver::Instance<'m>,
        e: &Expr,
        leaves: &mut Vec<(usize, usize)>,
        pointwise: &[(String, Val)],
        region_names: &mut Vec<String>,
        binding: &Binding<'m>,
    ) -> Result<Expr, CaseError> {
        let d = ops.asm.mesh().dim();
        let mut add = |o: &mut Self, m: Measure, comps: usize, span| {
            o.measures.push(m);
            let id = o.measures.len() - 1;
            leaves.push((id, comps));
            Expr { kind: ExprKind::Name(Ident { name: placeholder(id), span }), span }
        };
        let component = |a: &Expr| -> (u8, usize) {
            let ExprKind::Index(f, k) = &a.kind else { unreachable!("checked: u[k] or v[k]") };
            let field = matches!(&f.kind, ExprKind::Name(n) if n.name == "v") as u8;
            (field, crate::compiler::check::const_value(k).unwrap_or(0.0) as usize)
        };
        let bad_axis = |a: &Expr, axis: usize| {
            pf.render(crate::compiler::Diagnostic::error(
                "E0302",
                "wrong dimension",
                a.span,
                format!("component {axis} of a field in a {d}D problem"),
            ))
        };
        Ok(match &e.kind {
            ExprKind::Number(_) => e.clone(),
            ExprKind::Name(id) => {
                // An earlier column first: `series energy = energy` is then read, not measured
                // again, by the columns after it.
                let column = self.columns.iter().position(|(n, _, _)| *n == id.name).map(Measure::Column);
                let row = column.or(match id.name.as_str() {
                    "t" => Some(Measure::Time),
                    "energy" => Some(Measure::Energy),
                    "kinetic" => Some(Measure::Kinetic),
                    "newton" => Some(Measure::Newton),
                    "active_points" => Some(Measure::ActivePoints),
                    "status_kept" => Some(Measure::StatusKept),
                    _ => None,
                });
                match row {
                    Some(m) => add(self, m, 1, e.span),
                    None => e.clone(), // a param or a let
                }
            }
            ExprKind::Neg(a) => {
                let a = self.rewrite(pf, ex, ops, inst, a, leaves, pointwise, region_names, binding)?;
                Expr { kind: ExprKind::Neg(Box::new(a)), span: e.span }
            }
            ExprKind::Binary(op, a, b) => {
                let a = self.rewrite(pf, ex, ops, inst, a, leaves, pointwise, region_names, binding)?;
                let b = self.rewrite(pf, ex, ops, inst, b, leaves, pointwise, region_names, binding)?;
                Expr { kind: ExprKind::Binary(*op, Box::new(a), Box::new(b)), span: e.span }
            }
            ExprKind::Index(a, k) => {
                let a = self.rewrite(pf, ex, ops, inst, a, leaves, pointwise, region_names, binding)?;
                Expr { kind: ExprKind::Index(Box::new(a), k.clone()), span: e.span }
            }
            ExprKind::Vector(_) => unreachable!("checked: no vector in a column"),
            ExprKind::Call(f, args) => match crate::compiler::check::problem::row_reducer(&f.name).map(|r| r.kind) {
                None if crate::compiler::check::problem::row_function(&f.name).is_some() => {
                    let args = args
                        .iter()
                        .map(|a| self.rewrite(pf, ex, ops, inst, a, leaves, pointwise, region_names, binding))
                        .collect::<Result<Vec<_>, _>>()?;
                    Expr { kind: ExprKind::Call(f.clone(), args), span: e.span }
                }
                Some(kind @ (R::Mean | R::NodalMean | R::AtMin)) => {
                    let (field, axis) = component(&args[0]);
                    if axis >= d {
                        return Err(bad_axis(&args[0], axis));
                    }
                    let m = match kind {
                        R::Mean => Measure::Mean { field, weights: ops.axis_mean(axis) },
                        R::NodalMean => Measure::NodalMean { field, axis },
                        _ => {
                            let val = ex.lower(&args[1], &[]).map_err(|e| pf.render(*e))?;
                            let key = ex.function(&val, &args[1]).map_err(|e| pf.render(*e))?;
                            let mesh = ops.asm.mesh();
                            let (mut scratch, mut out) = (Vec::new(), [0.0]);
                            let mut at = |i: usize| {
                                key.eval(&At { x: mesh.node(i), ..At::default() }, &mut scratch, &mut out);
                                out[0]
                            };
                            let values: Vec<f64> = (0..mesh.num_nodes()).map(&mut at).collect();
                            let node = (0..mesh.num_nodes())
                                .min_by(|&a, &b| values[a].total_cmp(&values[b]))
                                .ok_or_else(|| CaseError::Option("the mesh has no node".into()))?;
                            let massless = ops.redistributed && ops.contact_nodes.contains(&(node as u32));
                            Measure::AtMin { field, axis, node, massless }
                        }
                    };
                    add(self, m, 1, e.span)
                }
                Some(kind @ (R::Force | R::Work)) => {
                    let ExprKind::Name(slot) = &args[0].kind else { unreachable!("checked: a slot name") };
                    let index = match self.slots.iter().position(|(n, _)| *n == slot.name) {
                        Some(i) => i,
                        None => {
                            let form = inst.take_form(&slot.name).ok_or_else(|| {
                                pf.render(crate::compiler::Diagnostic::error(
                                    "E0101",
                                    format!("no form of the files in use provides slot `{}`", slot.name),
                                    slot.span,
                                    "not provided",
                                ))
                            })?;
                            self.slots.push((slot.name.clone(), form));
                            self.slots.len() - 1
                        }
                    };
                    if kind == R::Work {
                        return Ok(add(self, Measure::Work { slot: index }, 1, e.span));
                    }
                    // Over a region: the dofs of its nodes, component by component.
                    let dofs = match args.get(1).map(|a| &a.kind) {
                        Some(ExprKind::Name(region)) => {
                            let mesh = ops.asm.mesh();
                            let nodes = mesh.region_nodes(mesh.region(&region.name)?);
                            Some(nodes.iter().flat_map(|&n| (0..d).map(move |k| n as usize * d + k)).collect())
                        }
                        _ => None,
                    };
                    add(self, Measure::Force { slot: index, dofs }, d, e.span)
                }
                Some(kind @ (R::Cumulative | R::Initial)) => {
                    let ExprKind::Name(id) = &args[0].kind else { unreachable!("checked: a column's name") };
                    let column = self.columns.iter().position(|(n, _, _)| *n == id.name).ok_or_else(|| {
                        pf.render(crate::compiler::Diagnostic::error(
                            "E0101",
                            format!("no earlier column `{}` on this run", id.name),
                            id.span,
                            "not measured",
                        ))
                    })?;
                    let sum = kind == R::Cumulative;
                    let value = std::cell::Cell::new(if sum { 0.0 } else { f64::NAN });
                    add(self, Measure::OverRows { column, sum, value }, 1, e.span)
                }
                Some(R::InnerMass) => {
                    let mut field = |e: &Expr| -> Result<PointFn, CaseError> {
                        let val = ex.lower(e, pointwise).map_err(|d| pf.render(*d))?;
                        ex.function(&val, e).map_err(|d| pf.render(*d))
                    };
                    let (a, b) = (field(&args[0])?, field(&args[1])?);
                    add(self, Measure::InnerMass { a, b }, 1, e.span)
                }
                Some(kind @ (R::DensityMin | R::DensitySupport)) => {
                    let ExprKind::Call(name, _) = &args[0].kind else { unreachable!("checked: a functional") };
                    let known = self.functionals.iter().position(|(n, _)| *n == name.name);
                    let index = match known {
                        Some(i) => i,
                        None => {
                            let func = inst.take_functional(&name.name).ok_or_else(|| {
                                pf.render(crate::compiler::Diagnostic::error(
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
                    // Its integrand must live on facets: a cell functional has none to read.
                    let rule = crate::runtime::fem::quadrature::sampling_rule(d - 1, 1);
                    let zero = vec![0.0; ops.asm.size()];
                    if self.functionals[index].1.facet_point_values(ops.asm, &rule, &[&zero], 0.0).is_empty() {
                        return Err(pf.render(crate::compiler::Diagnostic::error(
                            "E0301",
                            format!("`{}` integrates over no boundary facet", name.name),
                            name.span,
                            "no facet to sample",
                        )
                        .with_help("density_min and density_support read a functional over a boundary region: `int(Gamma_C) ...`")));
                    }
                    add(self, Measure::Density { index, min: kind == R::DensityMin }, 1, e.span)
                }
                Some(kind @ (R::Measure | R::Peak)) => {
                    let ExprKind::Name(region) = &args[0].kind else { unreachable!("checked: a region name") };
                    let facets = binding
                        .regions
                        .iter()
                        .find(|(n, _)| *n == region.name)
                        .map(|(_, f)| *f)
                        .ok_or_else(|| CaseError::Option(format!("region `{}` is not bound", region.name)))?;
                    let index = match region_names.iter().position(|n| *n == region.name) {
                        Some(i) => i,
                        None => {
                            region_names.push(region.name.clone());
                            self.regions.push(facets);
                            self.regions.len() - 1
                        }
                    };
                    let val = ex.lower(&args[1], pointwise).map_err(|e| pf.render(*e))?;
                    let pf_fn = ex.function(&val, &args[1]).map_err(|e| pf.render(*e))?;
                    let m = if kind == R::Measure {
                        Measure::Area { region: index, f: pf_fn }
                    } else {
                        Measure::Peak { region: index, f: pf_fn }
                    };
                    add(self, m, 1, e.span)
                }
                None => {
                    let name = f.name.as_str();
                    let at: Vec<Level> = args
                        .iter()
                        .map(|a| match &a.kind {
                            ExprKind::Name(n) if n.name == "u_mid" => Level::Mid,
                            ExprKind::Name(n) if n.name == "u_prev" => Level::Start,
                            _ => Level::Now,
                        })
                        .collect();
                    let mid = at.contains(&Level::Mid);
                    let by_reference = self.reference.as_ref().and_then(|(r, _)| {
                        r.functionals()
                            .iter()
                            .position(|(n, _)| *n == name)
                            .map(|which| Measure::Reference { which, mid })
                    });
                    let known = self.functionals.iter().position(|(n, _)| n == name);
                    let index = known.or_else(|| {
                        let f = inst.take_functional(name)?;
                        self.functionals.push((name.to_string(), f));
                        Some(self.functionals.len() - 1)
                    });
                    if let Some(i) = index
                        && self.functionals[i].1.fields() != at.len()
                    {
                        let fields = self.functionals[i].1.fields();
                        let d = crate::compiler::Diagnostic::error(
                            "E0201",
                            format!("`{name}` takes {fields} state(s)"),
                            e.span,
                            format!("{} given", at.len()),
                        )
                        .with_help(if fields == 2 {
                            format!("write `{name}(u, u_prev)`: the step's end and start")
                        } else {
                            format!("write `{name}(u)`")
                        });
                        return Err(pf.render(d));
                    }
                    let m = match index {
                        Some(index) => Measure::Functional { index, at },
                        None => by_reference.ok_or_else(|| {
                            let mut d = crate::compiler::Diagnostic::error(
                                "E0101",
                                format!("no functional `{name}` in the files in use"),
                                f.span,
                                "not provided",
                            );
                            match &self.reference {
                                Some((r, _)) => {
                                    let names: Vec<&str> = r.functionals().iter().map(|(n, _)| *n).collect();
                                    d = d.with_note(format!("nor in reference `{}`: {}", r.name(), names.join(", ")));
                                    if let Some(s) = crate::compiler::check::suggest_name(name, names.iter().copied()) {
                                        d = d.with_help(format!("did you mean `{s}`?"));
                                    }
                                }
                                None => d = d.with_note("the problem names no reference (`reference NAME`)"),
                            }
                            pf.render(d)
                        })?,
                    };
                    add(self, m, 1, e.span)
                }
            },
        })
    }
}
