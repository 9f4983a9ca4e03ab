//! Assembly through the runtime alone (a hand-written form, no compiler), on every element kind
//! of the catalogue: the mass matrix integrates to ρ|Ω| per component, the stiffness gives
//! ∫|∇x₁|² = |Ω| for the interpolated linear field x₁ and annihilates constants, matrices are
//! symmetric, and the residual of a linear form is its tangent times the field; a process's part
//! of a mesh (a run split across processes) assembles its rows whole.

use crate::common::{MassStiffness, pseudo_random};
use signorini_runtime::fem::assembly::{Assembler, CellIntegral, CellOrder, Quadrature};
use signorini_runtime::fem::mesh::Mesh;
use signorini_runtime::fem::mesh::ball::ball;
use signorini_runtime::fem::mesh::structured::{Diagonal, cuboid, interval, rectangle};

/// The unit interval, square and cube in P1 and P2 (volume 1).
fn unit_meshes() -> Vec<Mesh> {
    let unit = [0.0, 1.0];
    vec![
        interval(7, 0.0, 1.0),
        rectangle(3, 4, unit, unit, Diagonal::Right, 1),
        rectangle(3, 4, unit, unit, Diagonal::Left, 2),
        cuboid([2, 3, 2], unit, unit, unit, 1),
        cuboid([2, 2, 3], unit, unit, unit, 2),
    ]
}

fn quad(m: &signorini_runtime::linalg::Matrix, x: &[f64], y: &[f64]) -> f64 {
    let mut my = vec![0.0; y.len()];
    m.mul_vec(y, &mut my);
    x.iter().zip(&my).map(|(a, b)| a * b).sum()
}

#[test]
fn mass_and_stiffness_on_every_element_kind() {
    for mesh in unit_meshes() {
        let (d, name) = (mesh.dim(), mesh.kind.name());
        let asm = Assembler::new(&mesh);
        let n = asm.size();
        let zero = vec![0.0; n];
        let mut m = asm.zero_matrix();
        asm.cell_tangent(
            CellIntegral::all(&MassStiffness { rho: 2.0, k: 0.0 }, Quadrature::default()),
            &[&zero],
            0,
            0.0,
            &mut m,
        );
        let mut k = asm.zero_matrix();
        asm.cell_tangent(
            CellIntegral::all(&MassStiffness { rho: 0.0, k: 1.0 }, Quadrature::default()),
            &[&zero],
            0,
            0.0,
            &mut k,
        );
        assert!(m.is_symmetric(1e-14) && k.is_symmetric(1e-14), "{name}");
        for a in 0..d {
            // The unit field of component a: mass ρ|Ω|, no strain energy.
            let e: Vec<f64> = (0..n).map(|i| if i % d == a { 1.0 } else { 0.0 }).collect();
            assert!((quad(&m, &e, &e) - 2.0).abs() < 1e-12, "{name}: mass {}", quad(&m, &e, &e));
            let mut ke = vec![0.0; n];
            k.mul_vec(&e, &mut ke);
            assert!(ke.iter().all(|x| x.abs() < 1e-12), "{name}: K annihilates constants");
            // u_a = x_a, interpolated exactly by P1 and P2: ∫|∇u|² = |Ω| = 1.
            let x: Vec<f64> = (0..n).map(|i| if i % d == a { mesh.node(i / d)[a] } else { 0.0 }).collect();
            assert!((quad(&k, &x, &x) - 1.0).abs() < 1e-12, "{name}: energy {}", quad(&k, &x, &x));
        }
        // A linear form's residual is its tangent times the field.
        let form = MassStiffness { rho: 1.5, k: 0.7 };
        let mut t = asm.zero_matrix();
        asm.cell_tangent(CellIntegral::all(&form, Quadrature::default()), &[&zero], 0, 0.0, &mut t);
        let u = pseudo_random(n, 7);
        let mut r = vec![0.0; n];
        asm.cell_residual(CellIntegral::all(&form, Quadrature::default()), &[&u], 0.0, &mut r);
        let mut tu = vec![0.0; n];
        t.mul_vec(&u, &mut tu);
        let scale = tu.iter().fold(0.0f64, |s, x| s.max(x.abs()));
        assert!(r.iter().zip(&tu).all(|(a, b)| (a - b).abs() < 1e-13 * scale), "{name}: R(u) ≠ T u");
    }
}

#[test]
fn the_curved_ball_has_the_mass_of_its_volume() {
    let mesh = ball(1.0, [0.0, 0.0, 0.0], 0.25);
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let mut m = asm.zero_matrix();
    // Degree 6: the curved cells' Jacobians are polynomials of degree 6 in the reference cell.
    let q = Quadrature { cell: Some(6), facet: None };
    asm.cell_tangent(CellIntegral::all(&MassStiffness { rho: 1.0, k: 0.0 }, q), &[&vec![0.0; n]], 0, 0.0, &mut m);
    let e: Vec<f64> = (0..n).map(|i| if i % 3 == 0 { 1.0 } else { 0.0 }).collect();
    let volume = 4.0 / 3.0 * std::f64::consts::PI;
    assert!((quad(&m, &e, &e) - mesh.measure()).abs() < 1e-12 * volume);
    // The isoparametric ball's volume error at h = R/4 (O(h⁴): 2.8e-5 at h = R/4).
    assert!((mesh.measure() - volume).abs() < 5e-5 * volume, "{}", mesh.measure());
}

#[test]
fn blocks_of_a_colour_share_no_node_and_cover_every_cell_once() {
    for mesh in unit_meshes().into_iter().chain([ball(1.0, [0.0, 0.0, 0.0], 0.4)]) {
        let asm = Assembler::new(&mesh);
        for order in [asm.cell_order().clone(), CellOrder::new(&mesh, 1), CellOrder::new(&mesh, 3)] {
            let mut seen = vec![0usize; mesh.num_cells()];
            let mut blocks = vec![0usize; order.num_blocks()];
            for colour in order.colours() {
                let mut owner = vec![usize::MAX; mesh.num_nodes()];
                assert!(colour.windows(2).all(|w| w[0] < w[1]), "sorted");
                for &b in colour {
                    blocks[b as usize] += 1;
                    for c in order.block(b as usize) {
                        seen[c] += 1;
                        for &n in mesh.cell(c) {
                            let o = owner[n as usize];
                            let name = mesh.kind.name();
                            assert!(o == usize::MAX || o == b as usize, "{name}: node {n} in two blocks of a colour");
                            owner[n as usize] = b as usize;
                        }
                    }
                }
            }
            assert!(blocks.iter().all(|&k| k == 1), "every block once");
            assert!(seen.iter().all(|&k| k == 1), "every cell once");
        }
    }
}

#[test]
fn threaded_assembly_has_the_same_bits_on_one_and_two_threads() {
    let mesh = ball(1.0, [0.0, 0.0, 0.0], 0.25);
    let asm = Assembler::new(&mesh);
    let n = asm.size();
    let u = pseudo_random(n, 3);
    let form = MassStiffness { rho: 1.5, k: 0.7 };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a pool");
        pool.install(|| {
            let mut m = asm.zero_matrix();
            asm.cell_tangent(CellIntegral::all(&form, Quadrature::default()), &[&u], 0, 0.0, &mut m);
            let mut r = vec![0.0; n];
            asm.cell_residual(CellIntegral::all(&form, Quadrature::default()), &[&u], 0.0, &mut r);
            (m.values, r)
        })
    };
    let (m1, r1) = run(1);
    let (m2, r2) = run(2);
    let colours = asm.cell_order().colours();
    assert!(colours.iter().any(|c| c.len() > 2), "several blocks in a colour: {colours:?}");
    assert!(m1.iter().zip(&m2).all(|(a, b)| a.to_bits() == b.to_bits()), "matrix bits");
    assert!(r1.iter().zip(&r2).all(|(a, b)| a.to_bits() == b.to_bits()), "residual bits");
}

#[test]
fn each_process_part_holds_its_rows_whole_and_the_parts_own_every_cell_once() {
    // Three processes, owning slabs of nodes along x (an uneven split, as a partitioner's).
    for mesh in [ball(1.0, [0.0, 0.0, 0.0], 0.3), cuboid([3, 2, 2], [0.0, 1.0], [0.0, 1.0], [0.0, 1.0], 2)] {
        let name = mesh.kind.name();
        let owner: Vec<u32> = (0..mesh.num_nodes())
            .map(|i| {
                let x = mesh.node(i)[0];
                if x < -0.2 || (x < 0.3 && mesh.node(i)[1] > 0.5) {
                    0
                } else if x < 0.55 {
                    1
                } else {
                    2
                }
            })
            .collect();
        let whole = Assembler::new(&mesh);
        let n = whole.size();
        let form = MassStiffness { rho: 1.5, k: 0.7 };
        let u = pseudo_random(n, 11);
        let (mut m, mut r) = (whole.zero_matrix(), vec![0.0; n]);
        whole.cell_tangent(CellIntegral::all(&form, Quadrature::default()), &[&u], 0, 0.0, &mut m);
        whole.cell_residual(CellIntegral::all(&form, Quadrature::default()), &[&u], 0.0, &mut r);
        let mut mu = vec![0.0; n];
        m.mul_vec(&u, &mut mu);
        let scale = r.iter().chain(&mu).fold(0.0f64, |s, x| s.max(x.abs()));
        let mut owned_cells: Vec<Vec<u32>> = Vec::new();
        for rank in 0..3u32 {
            let regions: Vec<&str> = mesh.regions.iter().map(|r| r.name.as_str()).collect();
            let (part, owned) = mesh.part(&owner, rank, &regions[1..]);
            // The cells it owns are those whose first node it owns.
            for c in 0..part.num_cells() {
                assert_eq!(c < owned, owner[part.cell(c)[0] as usize] == rank, "{name}: owned cells first");
            }
            owned_cells.extend((0..owned).map(|c| part.cell(c).to_vec()));
            // Every region named keeps its facets, in order, on the same cells; the others are
            // left out.
            assert_eq!(part.regions.len(), mesh.regions.len() - 1, "{name}: the first region left out");
            for (a, b) in mesh.regions[1..].iter().zip(&part.regions) {
                assert_eq!(a.facets.len(), b.facets.len(), "{name}: region {}", a.name);
                for (f, g) in a.facets.iter().zip(&b.facets) {
                    assert_eq!((mesh.cell(f.cell as usize), f.local), (part.cell(g.cell as usize), g.local));
                }
            }
            // Assembled on the part alone, the rows of its nodes are the whole mesh's.
            let asm = Assembler::new(&part);
            let (mut mp, mut rp) = (asm.zero_matrix(), vec![0.0; n]);
            asm.cell_tangent(CellIntegral::all(&form, Quadrature::default()), &[&u], 0, 0.0, &mut mp);
            asm.cell_residual(CellIntegral::all(&form, Quadrature::default()), &[&u], 0.0, &mut rp);
            let mut mpu = vec![0.0; n];
            mp.mul_vec(&u, &mut mpu);
            let d = mesh.dim();
            let mine: Vec<usize> = (0..n).filter(|&i| owner[i / d] == rank).collect();
            assert!(!mine.is_empty() && mine.len() < n, "{name}: rank {rank} owns some rows");
            for &i in &mine {
                assert!((rp[i] - r[i]).abs() <= 1e-13 * scale, "{name}: rank {rank}, residual row {i}");
                assert!((mpu[i] - mu[i]).abs() <= 1e-13 * scale, "{name}: rank {rank}, matrix row {i}");
            }
            // And some other row is not (the part does not hold every cell).
            assert!((0..n).any(|i| (mpu[i] - mu[i]).abs() > 1e-8 * scale), "{name}: rank {rank} holds a part");
        }
        // The owned cells of the three parts are the mesh's cells, each once.
        let mut all: Vec<Vec<u32>> = (0..mesh.num_cells()).map(|c| mesh.cell(c).to_vec()).collect();
        all.sort();
        owned_cells.sort();
        assert_eq!(owned_cells, all, "{name}: every cell owned once");
    }
}
