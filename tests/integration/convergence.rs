//! Manufactured solutions for linear elasticity through the library's compiled forms (`signorini
//! verify`'s (b)): P1 and P2 in 1D, 2D (straight meshes, and the curved isoparametric P2 disc)
//! and 3D. Observed rates on the two finest meshes must reach p + 1 − 0.1 in L2 and p − 0.1 in H1.

#[test]
fn p1_and_p2_reach_their_orders_in_one_two_and_three_dimensions() {
    let rows = signorini::verify::space::orders(&mut |_| {}).unwrap();
    // 1D P1; 2D P1 and P2 with two diagonals each; the curved disc; 3D P1 and P2.
    assert_eq!(rows.len(), 8);
    for r in &rows {
        let p = r.degree as f64;
        eprintln!("{} P{}: {:?}, rates L2 {:.3} H1 {:.3}", r.case, r.degree, r.errors, r.l2_order, r.h1_order);
        assert!(r.l2_order >= p + 0.9, "{} P{}: L2 rate {:.3}", r.case, r.degree, r.l2_order);
        assert!(r.h1_order >= p - 0.1, "{} P{}: H1 rate {:.3}", r.case, r.degree, r.h1_order);
    }
}
