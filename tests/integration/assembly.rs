//! Global assembly: the P2 plane-strain stiffness of the benchmark against the Frobenius norm
//! DOLFINx, GetFEM and FEniCS agree on, mass totals, symmetry, and vectors against matrices.

use signorini::runtime::fem::assembly::{Assembler, CellIntegral, Quadrature};
use signorini::runtime::fem::kernel::Coef;
use signorini::runtime::fem::mesh::structured::{self, Diagonal};

signorini::forms!("forms/elasticity.wf");

fn forms(nu: f64, f: Vec<f64>) -> (elasticity::Stiffness, elasticity::Mass, elasticity::Load) {
    let p = elasticity::Params::default().with("nu", nu).unwrap();
    let c = elasticity::Coefficients { f: Coef::constant(f) };
    (elasticity::Stiffness::new(&p, &c), elasticity::Mass::new(&p, &c), elasticity::Load::new(&p, &c))
}

#[test]
fn p2_stiffness_frobenius_norm_matches_the_reference_value() {
    let mesh = structured::rectangle(64, 64, [0.0, 1.0], [0.0, 1.0], Diagonal::Right, 2);
    let asm = Assembler::new(&mesh);
    let (k, _, _) = forms(0.3, vec![0.0, 0.0]);
    let zero = vec![0.0; asm.size()];
    let mut kmat = asm.zero_matrix();
    asm.cell_tangent(CellIntegral::all(&k, Quadrature { cell: Some(2), facet: None }), &[&zero], 0, 0.0, &mut kmat);
    // DOLFINx, GetFEM and FEniCS agree to ten digits on 988.894321.
    assert!((kmat.frobenius() - 988.894321).abs() < 1e-6, "{}", kmat.frobenius());
}

#[test]
fn assembled_matrices_are_symmetric_and_mass_totals_are_exact() {
    let mesh = structured::rectangle(6, 4, [0.0, 1.5], [0.0, 1.0], Diagonal::Left, 2);
    let asm = Assembler::new(&mesh);
    let (k, m, load) = forms(0.25, vec![0.3, -2.0]);
    let zero = vec![0.0; asm.size()];
    let (mut kmat, mut mmat) = (asm.zero_matrix(), asm.zero_matrix());
    asm.cell_tangent(CellIntegral::all(&k, Quadrature::default()), &[&zero], 0, 0.0, &mut kmat);
    asm.cell_tangent(CellIntegral::all(&m, Quadrature::default()), &[&zero], 0, 0.0, &mut mmat);
    let n = asm.size();
    for i in 0..n {
        for j in 0..n {
            assert!((kmat.get(i, j) - kmat.get(j, i)).abs() < 1e-13);
            assert!((mmat.get(i, j) - mmat.get(j, i)).abs() < 1e-15);
        }
    }
    // 1ᵀ M 1 = ρ |Ω| d, and the residual of `mass` at a is M a.
    assert!((mmat.values.iter().sum::<f64>() - 1.5 * 2.0).abs() < 1e-13);
    let a: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
    let (mut ma, mut r) = (vec![0.0; n], vec![0.0; n]);
    mmat.mul_vec(&a, &mut ma);
    asm.cell_residual(CellIntegral::all(&m, Quadrature::default()), &[&a], 0.0, &mut r);
    assert!(ma.iter().zip(&r).all(|(x, y)| (x - y).abs() < 1e-14));
    // Load of a constant force: total force per component = f |Ω|.
    let mut l = vec![0.0; n];
    asm.cell_residual(CellIntegral::all(&load, Quadrature::default()), &[], 0.0, &mut l);
    let fx: f64 = l.iter().step_by(2).sum();
    let fy: f64 = l.iter().skip(1).step_by(2).sum();
    assert!((fx - 0.3 * 1.5).abs() < 1e-13 && (fy + 2.0 * 1.5).abs() < 1e-13);
}
