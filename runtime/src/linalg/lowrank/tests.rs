use super::*;
use crate::fem::assembly::Assembler;
use crate::fem::mesh::structured::{Diagonal, cuboid, rectangle};
use crate::fem::test_matrices::diagonally_dominant;
use crate::linalg::factorization::Structure;

#[test]
fn dense_columns_hold_each_column_over_the_union_of_their_nodes() {
    // d = 2, nodes increasing in each column.
    let columns = [
        SparseColumn { nodes: vec![1, 4], values: vec![1.0, 2.0, 3.0, 4.0] },
        SparseColumn { nodes: vec![0, 7], values: vec![7.0, 8.0, 5.0, 6.0] },
        SparseColumn { nodes: vec![4, 7], values: vec![9.0, 10.0, 11.0, 12.0] },
    ];
    let refs: Vec<&SparseColumn> = columns.iter().collect();
    let dense = DenseColumns::new(&refs, 2, 8, usize::MAX, &mut vec![f64::NAN; 3]).expect("small");
    assert_eq!(dense.nodes, [0, 1, 4, 7]);
    let expected = [
        [0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 0.0, 0.0],
        [7.0, 8.0, 0.0, 0.0, 0.0, 0.0, 5.0, 6.0],
        [0.0, 0.0, 0.0, 0.0, 9.0, 10.0, 11.0, 12.0],
    ];
    assert_eq!(dense.values, expected.concat());
}

#[test]
fn rank_one_terms_of_element_changes_correct_the_factor() {
    let unit = [0.0, 1.0];
    let mesh = rectangle(10, 8, unit, unit, Diagonal::Right, 2);
    let asm = Assembler::new(&mesh);
    let a = diagonally_dominant(&asm);
    let (n, d) = (a.size(), 2);
    // Elements on five cells, zero at the reference; two change, by a rank-one and a
    // rank-two symmetric matrix (one term negative).
    let cells = [3usize, 17, 40, 41, 77];
    let s = 6 * d;
    let dofs: Vec<usize> = cells
        .iter()
        .flat_map(|&c| mesh.cell(c).iter().flat_map(|&node| (0..d).map(move |m| node as usize * d + m)))
        .collect();
    let reference = ElementMatrices { size: s, dofs: dofs.clone(), values: vec![0.0; cells.len() * s * s] };
    let mut current = reference.clone();
    let v = |k: usize| (0..s).map(|i| ((i * 7 + k * 3) % 11) as f64 / 11.0 - 0.3).collect::<Vec<f64>>();
    for (e, terms) in [(1usize, vec![(2.0, v(0))]), (3, vec![(1.5, v(1)), (-0.25, v(2))])] {
        for (lambda, x) in terms {
            for i in 0..s {
                for j in 0..s {
                    current.values[(e * s + i) * s + j] += lambda * x[i] * x[j];
                }
            }
        }
    }
    // J = J₀ + the elements' assembly.
    let mut j = a.clone();
    for (e, block) in current.values.chunks_exact(s * s).enumerate() {
        for (r, &row) in dofs[e * s..(e + 1) * s].iter().enumerate() {
            for (c, &col) in dofs[e * s..(e + 1) * s].iter().enumerate() {
                let p = &j.pattern;
                let k = p.col_ptr[col] + p.row_idx[p.col_ptr[col]..p.col_ptr[col + 1]].binary_search(&row).unwrap();
                j.values[k] += block[r * s + c];
            }
        }
    }
    let mut f = Factorization::new(Structure::SymmetricPositiveDefinite);
    f.factor(&a).unwrap();
    // A system larger than allowed is refused: three terms, more dofs.
    let mut small = LowRank::new(&a);
    small.set_elements(Some(reference.clone()));
    let changed = small.changed_dofs(&j, None);
    assert!(!small.update(&j, changed, &mut f, Some(&current), 2).unwrap(), "three terms, at most two");
    let mut lr = LowRank::new(&a);
    lr.set_elements(Some(reference));
    let changed = lr.changed_dofs(&j, None);
    assert!(lr.update(&j, changed.clone(), &mut f, Some(&current), usize::MAX).unwrap());
    assert_eq!(lr.terms(), 3, "three rank-one terms for {} changed dofs", changed.len());
    assert!(changed.len() > 3);
    let b: Vec<f64> = (0..n).map(|i| ((i * 13) % 23) as f64 / 23.0 - 0.5).collect();
    let mut x = b.clone();
    let defect = lr.solve(&mut f, &mut x, true).unwrap().expect("a Cholesky reference in node blocks");
    // J x = b, and the residual the terms' correction reports is as small.
    let mut jx = vec![0.0; n];
    j.mul_vec(&x, &mut jx);
    let err = jx.iter().zip(&b).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    assert!(err < 1e-12, "residual {err:.1e}");
    assert!(defect < 1e-12, "defect {defect:.1e}");
    // Without the elements, the correction by E on the changed dofs solves alike.
    let mut by_dofs = LowRank::new(&a);
    assert!(by_dofs.update(&j, changed.clone(), &mut f, None, usize::MAX).unwrap());
    assert_eq!(by_dofs.terms(), changed.len());
    let mut y = b.clone();
    by_dofs.solve(&mut f, &mut y, false).unwrap();
    let diff = x.iter().zip(&y).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    assert!(diff < 1e-12, "the two corrections differ by {diff:.1e}");
}

#[test]
fn entries_that_differ_by_round_off_are_no_change() {
    let unit = [0.0, 1.0];
    let mesh = rectangle(6, 5, unit, unit, Diagonal::Right, 2);
    let a = diagonally_dominant(&Assembler::new(&mesh));
    let lr = LowRank::new(&a);
    let (col, k) = (7, a.pattern.col_ptr[7]);
    let row = a.pattern.row_idx[k + 1];
    let at = |relative: f64| {
        let mut j = a.clone();
        j.values[k + 1] *= 1.0 + relative;
        lr.changed_dofs(&j, None)
    };
    assert!(at(4.0 * f64::EPSILON).is_empty(), "a few ulps");
    let mut both = vec![col, row];
    both.sort_unstable();
    assert_eq!(at(1e-10), both, "a change of 1e-10 is one");
}

#[test]
fn dense_and_sparse_columns_correct_alike() {
    let unit = [0.0, 1.0];
    for mesh in [rectangle(12, 9, unit, unit, Diagonal::Right, 2), cuboid([3, 3, 2], unit, unit, unit, 1)] {
        let a = diagonally_dominant(&Assembler::new(&mesh));
        let n = a.size();
        let mut f = Factorization::new(Structure::SymmetricPositiveDefinite);
        f.factor(&a).unwrap();
        let block = f.block().expect("node blocks");
        let d = block.dim();
        // Columns of W for dofs spread over the mesh (their supports differ), and a
        // nonsymmetric E with M = I + G E well conditioned.
        let dofs: Vec<usize> = (0..n).step_by(n / 7).collect();
        let k = dofs.len();
        let mut work = vec![0.0; n];
        let columns: Vec<SparseColumn> =
            dofs.iter().map(|&i| block.forward_unit(block.position(i), &mut work)).collect();
        let cols: Vec<&SparseColumn> = columns.iter().collect();
        let e: Vec<f64> = (0..k * k).map(|i| 0.05 * ((i * 37 % 11) as f64 - 5.0) / 5.0).collect();
        let g = Mat::from_fn(k, k, |x, y| {
            scatter(cols[y], d, &mut work);
            let v = gather(cols[x], d, &work);
            unscatter(cols[y], d, &mut work);
            v
        });
        let m = Mat::<f64>::identity(k, k) + &g * Mat::from_fn(k, k, |x, y| e[x * k + y]);
        let lu = m.partial_piv_lu();
        let entries = columns.iter().map(|c| c.values.len()).sum();
        // Stored in memory holding other values (a previous correction's): overwritten whole.
        let mut spare = vec![7.0; 5 * n];
        let dense = DenseColumns::new(&cols, d, n / d, entries, &mut spare).expect("few columns: dense");
        let z: Vec<f64> = (0..n).map(|i| ((i * 29) % 97) as f64 / 97.0 - 0.5).collect();
        let (mut sparse_z, mut dense_z) = (z.clone(), z.clone());
        correct_sparse(&cols, d, &lu, &e, &mut sparse_z, None);
        dense.correct(&mut dense_z, d, &lu, &e, None);
        let scale = sparse_z.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        let err = sparse_z.iter().zip(&dense_z).fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
        assert!(err <= 1e-14 * scale, "{n} unknowns: differ by {err:.1e}");
        assert!(sparse_z != z, "the correction changes z");

        // Whatever y the small system is solved to (here a perturbed M's), the corrected
        // solve's residual is U E ρ with ρ = Wᵀz' − y: exact on the dofs D, zero elsewhere,
        // to the triangular passes' round-off.
        let perturbed = (&m + Mat::from_fn(k, k, |x, y| 1e-3 * (1.0 + ((x + 2 * y) % 5) as f64))).partial_piv_lu();
        let j_times = |x: &[f64]| {
            let mut jx = vec![0.0; n];
            a.mul_vec(x, &mut jx);
            for c in 0..k {
                jx[dofs[c]] += (0..k).map(|y| e[c * k + y] * x[dofs[y]]).sum::<f64>();
            }
            jx
        };
        let b: Vec<f64> = (0..n).map(|i| ((i * 13) % 31) as f64 / 31.0 - 0.5).collect();
        for sparse in [true, false] {
            let (mut x, mut rho, mut work) = (b.clone(), Vec::new(), Vec::new());
            block.solve_with(&mut x, &mut work, |z| match sparse {
                true => correct_sparse(&cols, d, &perturbed, &e, z, Some(&mut rho)),
                false => dense.correct(z, d, &perturbed, &e, Some(&mut rho)),
            });
            let mut expected = vec![0.0; n];
            for c in 0..k {
                expected[dofs[c]] = (0..k).map(|y| e[c * k + y] * rho[y]).sum();
            }
            let jx = j_times(&x);
            let residual: Vec<f64> = jx.iter().zip(&b).map(|(p, q)| p - q).collect();
            let size = crate::linalg::norms::norm_inf(&residual);
            let err = residual.iter().zip(&expected).fold(0.0f64, |s, (p, q)| s.max((p - q).abs()));
            let roundoff = 64.0 * f64::EPSILON * a.norm_inf() * crate::linalg::norms::norm_inf(&x);
            assert!(size > 1e3 * roundoff, "{n} unknowns: the perturbation shows ({size:.1e})");
            assert!(err <= roundoff, "{n} unknowns, sparse {sparse}: U E ρ misses J x − b by {err:.1e} of {size:.1e}");
        }
    }
}
