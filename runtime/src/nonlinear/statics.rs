//! Static problems assembled from compiled forms: S(u) + C(u) = L, where S is the stiffness
//! (a linear form K u, assembled once, or a material nonlinear in u, assembled at every
//! iterate), C a contact form on a boundary region, and L the loads; Dirichlet conditions on
//! chosen dofs, held at their values.

use crate::fem::assembly::Assembler;
use crate::fem::bound::BoundForm;
use crate::linalg::{Matrix, Structure};
use crate::nonlinear::problem::NonlinearProblem;

/// Dirichlet conditions: dofs held at given values (zero unless set).
#[derive(Clone, Debug, PartialEq)]
pub struct Constraints {
    pub fixed: Vec<bool>,
    pub values: Vec<f64>,
}

impl Constraints {
    pub fn none(size: usize) -> Self {
        Constraints { fixed: vec![false; size], values: vec![0.0; size] }
    }

    /// Holds `dof` at zero.
    pub fn fix(&mut self, dof: usize) {
        self.fixed[dof] = true;
    }

    /// Holds `dof` at `value`.
    pub fn fix_value(&mut self, dof: usize, value: f64) {
        self.fixed[dof] = true;
        self.values[dof] = value;
    }

    /// Holds the listed components of every node of a boundary region at `value(x)`.
    pub fn fix_region(
        &mut self,
        mesh: &crate::fem::mesh::Mesh,
        region: &str,
        components: &[usize],
        value: impl Fn(&[f64]) -> Vec<f64>,
    ) -> Result<(), crate::fem::mesh::MeshError> {
        let d = mesh.dim();
        let region = mesh.region(region)?;
        for node in mesh.region_nodes(region) {
            let v = value(mesh.node(node as usize));
            for &k in components {
                self.fix_value(node as usize * d + k, v[k]);
            }
        }
        Ok(())
    }

    /// Sets the constrained entries of `u` to their values.
    pub fn impose(&self, u: &mut [f64]) {
        for ((x, f), v) in u.iter_mut().zip(&self.fixed).zip(&self.values) {
            if *f {
                *x = *v;
            }
        }
    }

    pub fn dofs(&self) -> Vec<usize> {
        self.fixed.iter().enumerate().filter(|(_, f)| **f).map(|(i, _)| i).collect()
    }

    /// Zeroes the constrained entries of a vector.
    pub fn zero(&self, v: &mut [f64]) {
        v.iter_mut().zip(&self.fixed).filter(|(_, f)| **f).for_each(|(x, _)| *x = 0.0);
    }

    /// Replaces constrained rows and columns by the identity.
    pub fn apply(&self, m: &mut Matrix) {
        m.constrain(&self.dofs(), 1.0);
    }
}

/// Solves the linear system K u = b with Dirichlet conditions (lifted: b − K u_D on the free
/// dofs, the identity on the fixed ones), by Cholesky if `structure` says K is SPD.
pub fn solve_linear(
    k: &Matrix,
    b: &[f64],
    constraints: &Constraints,
    structure: Structure,
) -> Result<Vec<f64>, crate::linalg::LinalgError> {
    let n = b.len();
    let mut lift = vec![0.0; n];
    constraints.impose(&mut lift);
    let mut klift = vec![0.0; n];
    k.mul_vec(&lift, &mut klift);
    let mut rhs: Vec<f64> = b.iter().zip(&klift).map(|(bi, ki)| bi - ki).collect();
    constraints.impose(&mut rhs);
    let mut a = k.clone();
    constraints.apply(&mut a);
    let mut f = crate::linalg::Factorization::new(structure);
    f.factor(&a)?;
    f.solve_in_place(&mut rhs)?;
    Ok(rhs)
}

/// The stiffness term of a static problem: K, assembled once, or a form nonlinear in u.
enum Stiffness<'m> {
    Matrix(Matrix),
    Nonlinear(Box<dyn BoundForm + 'm>),
}

/// S(u) + C(u) − L = 0.
pub struct StaticContact<'m> {
    asm: &'m Assembler<'m>,
    stiffness: Stiffness<'m>,
    load: Vec<f64>,
    /// The largest term of the last residual.
    magnitude: f64,
    /// The contact form, bound to its boundary region.
    pub contact: Box<dyn BoundForm + 'm>,
    pub constraints: Constraints,
    structure: Structure,
    /// The previous level a contact law's `prev` reads: the state the equilibrium is sought
    /// from (zero, unless set), so a frictional law measures slip from there.
    pub previous: Vec<f64>,
    /// The time the contact form (its obstacle, its coefs) is evaluated at (0, unless set).
    pub time: f64,
}

impl<'m> StaticContact<'m> {
    /// Assembles `stiffness` once when it is linear in u; a nonlinear one is kept as a form.
    pub fn new(
        asm: &'m Assembler<'m>,
        stiffness: Box<dyn BoundForm + 'm>,
        load: Vec<f64>,
        contact: Box<dyn BoundForm + 'm>,
        constraints: Constraints,
        structure: Structure,
    ) -> Self {
        let n = asm.size();
        let zero = vec![0.0; n];
        let stiffness = if stiffness.linear() {
            let mut k = asm.zero_matrix();
            stiffness.tangent(asm, &[&zero], 0, 0.0, &mut k);
            Stiffness::Matrix(k)
        } else {
            Stiffness::Nonlinear(stiffness)
        };
        let mut load = load;
        constraints.zero(&mut load);
        StaticContact {
            asm,
            stiffness,
            load,
            magnitude: 0.0,
            contact,
            constraints,
            structure,
            previous: zero,
            time: 0.0,
        }
    }

    /// The contact form's arguments at `u`: u, and the previous level if the law reads it.
    fn args<'a>(&'a self, u: &'a [f64]) -> Vec<&'a [f64]> {
        crate::fem::bound::with_previous(self.contact.previous(), &[u], &self.previous)
    }

    /// Replaces the loads (the stiffness, and so a factorization, stay valid).
    pub fn set_load(&mut self, mut load: Vec<f64>) {
        self.constraints.zero(&mut load);
        self.load = load;
    }

    /// The contact term's residual C(u) (unconstrained).
    pub fn contact_residual(&self, u: &[f64]) -> Vec<f64> {
        let mut c = vec![0.0; u.len()];
        self.contact.residual(self.asm, &self.args(u), self.time, &mut c);
        c
    }
}

impl NonlinearProblem for StaticContact<'_> {
    fn node_coordinates(&self) -> Option<std::sync::Arc<[f64]>> {
        Some(self.asm.mesh().coords.as_slice().into())
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        use crate::linalg::norms::norm_inf;
        match &self.stiffness {
            Stiffness::Matrix(k) => k.mul_vec(u, r),
            Stiffness::Nonlinear(form) => {
                r.fill(0.0);
                form.residual(self.asm, &[u], self.time, r);
            }
        }
        let stiffness = norm_inf(r);
        self.contact.residual(self.asm, &self.args(u), self.time, r);
        // The contact term's size is that of K u + C(u) at worst plus K u's.
        self.magnitude = stiffness.max(norm_inf(r)).max(norm_inf(&self.load));
        r.iter_mut().zip(&self.load).for_each(|(ri, li)| *ri -= li);
        self.constraints.zero(r);
    }

    fn magnitude(&self) -> f64 {
        self.magnitude
    }

    fn active_set(&mut self, u: &[f64], out: &mut Vec<bool>) -> bool {
        let here = self.contact.switches(self.asm, &self.args(u), 0, self.time, out);
        // A nonlinear stiffness's tangent changes with u everywhere.
        let linear = matches!(self.stiffness, Stiffness::Matrix(_));
        // A split run's processes see their own facets' gates (see the stage problem's).
        linear && (self.contact.piecewise() || (here && self.asm.pattern().ownership().is_none()))
    }

    fn jacobian(&mut self, u: &[f64], j: &mut Matrix) {
        match &self.stiffness {
            Stiffness::Matrix(k) => j.values.copy_from_slice(&k.values),
            Stiffness::Nonlinear(form) => form.tangent(self.asm, &[u], 0, self.time, j),
        }
        self.contact.tangent(self.asm, &self.args(u), 0, self.time, j);
        self.constraints.apply(j);
    }

    fn jacobian_matrix(&self) -> Matrix {
        self.asm.zero_matrix()
    }

    fn structure(&self) -> Structure {
        self.structure
    }
}
