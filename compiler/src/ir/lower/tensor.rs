//! The tensor built-ins of finite strain (`det`, `inv`, `cofac`, `dev`, `skew`) written out per
//! component in scalar jets, so that their derivatives, evaluation and emitted Rust are those
//! of the scalar nodes they are made of. Tensors are d×d, d = 1, 2, 3, row-major.

use super::{Jet, Lowerer, Val};
use crate::syntax::ast::Shape;

impl Lowerer<'_> {
    /// The built-in `f` of the tensor `a`.
    pub(super) fn tensor_fn(&mut self, f: &str, a: &Val) -> Val {
        match f {
            "det" => Self::scalar(self.det(a)),
            "cofac" => self.cofac(a),
            "inv" => {
                // inv(A) = cofac(A)ᵀ / det(A): one division per component, no pivoting, so the
                // same formula (and tangent) wherever det(A) ≠ 0.
                let c = self.cofac(a);
                let det = self.row_expansion(a, &c);
                let d = self.d;
                let comps = (0..d * d).map(|k| self.jdiv(&c.c[(k % d) * d + k / d], &det)).collect();
                Val { shape: Shape::Tensor, c: comps }
            }
            "dev" => {
                // A − tr(A)/d I
                let d = self.d;
                let mut tr = self.constant(0.0);
                for i in 0..d {
                    tr = self.jadd(&tr, &a.c[i * d + i]);
                }
                let per_dim = self.constant(1.0 / d as f64);
                let mean = self.jmul(&per_dim, &tr);
                let comps = (0..d * d)
                    .map(|k| if k / d == k % d { self.jsub(&a.c[k], &mean) } else { a.c[k].clone() })
                    .collect();
                Val { shape: Shape::Tensor, c: comps }
            }
            "skew" => {
                // (A − Aᵀ)/2
                let d = self.d;
                let half = self.constant(0.5);
                let comps = (0..d * d)
                    .map(|k| {
                        let s = self.jsub(&a.c[k], &a.c[(k % d) * d + k / d]);
                        self.jmul(&half, &s)
                    })
                    .collect();
                Val { shape: Shape::Tensor, c: comps }
            }
            _ => unreachable!("checked tensor built-in `{f}`"),
        }
    }

    /// det(A), by expansion along the first row.
    fn det(&mut self, a: &Val) -> Jet {
        let c = self.cofac(a);
        self.row_expansion(a, &c)
    }

    /// Σ_j A_0j C_0j: the determinant, given the cofactors C of A.
    fn row_expansion(&mut self, a: &Val, c: &Val) -> Jet {
        let mut acc = self.constant(0.0);
        for j in 0..self.d {
            let p = self.jmul(&a.c[j], &c.c[j]);
            acc = self.jadd(&acc, &p);
        }
        acc
    }

    /// The cofactor matrix C_ij = (−1)^(i+j) M_ij (M the minors), which is det(A) inv(A)ᵀ.
    fn cofac(&mut self, a: &Val) -> Val {
        let d = self.d;
        let c = match d {
            1 => vec![self.constant(1.0)],
            2 => {
                let (b, cc) = (self.jneg(&a.c[2]), self.jneg(&a.c[1]));
                vec![a.c[3].clone(), b, cc, a.c[0].clone()]
            }
            _ => (0..9)
                .map(|k| {
                    // With cyclic indices the sign (−1)^(i+j) is in the order of the product.
                    let (i, j) = (k / 3, k % 3);
                    let at = |r: usize, s: usize| a.c[((i + r) % 3) * 3 + (j + s) % 3].clone();
                    let p = self.jmul(&at(1, 1), &at(2, 2));
                    let q = self.jmul(&at(1, 2), &at(2, 1));
                    self.jsub(&p, &q)
                })
                .collect(),
        };
        Val { shape: Shape::Tensor, c }
    }
}
