//! A problem's Dirichlet conditions: the components of a region's nodes (or of the node nearest
//! a point) held by elimination; at zero they are constraints alone, at other values or values
//! that move with `t` also the stepper's prescribed displacements.

use super::ProblemFile;
use super::expr::Exprs;
use crate::error::CaseError;
use crate::runtime::nonlinear::statics::Constraints;

/// The problem's Dirichlet conditions: the listed components of every node of each region
/// held, by elimination. Held at zero, they are the constraints alone; held at other values, or
/// at values that move with `t`, they are also the stepper's prescribed displacements (each
/// stage holds its displacement quantity at the values of its time).
pub(super) fn dirichlet(
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
pub(super) struct Held {
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
    pub(super) fn prescribed(
        &self,
        mesh: &crate::runtime::fem::mesh::Mesh,
    ) -> crate::runtime::time::stepper::Prescribed {
        let nodes: Vec<Vec<f64>> = (0..mesh.num_nodes()).map(|i| mesh.node(i).to_vec()).collect();
        let me = self.clone();
        crate::runtime::time::stepper::Prescribed {
            dofs: self.dofs.clone(),
            values: Box::new(move |t, out| me.eval(&nodes, t, out)),
        }
    }

    /// Whether every held value is zero at `t`: what the static driver, which holds them at
    /// zero, may settle the body under.
    pub(super) fn zero_at(&self, mesh: &crate::runtime::fem::mesh::Mesh, t: f64) -> bool {
        let nodes: Vec<Vec<f64>> = (0..mesh.num_nodes()).map(|i| mesh.node(i).to_vec()).collect();
        let mut g = vec![0.0; self.dofs.len()];
        self.eval(&nodes, t, &mut g);
        g.iter().all(|&x| x == 0.0)
    }

    /// Imposes the held values at `t0` on u₀ and their rate (a centred difference) on v₀.
    pub(super) fn initial(&self, mesh: &crate::runtime::fem::mesh::Mesh, t0: f64, u0: &mut [f64], v0: &mut [f64]) {
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
