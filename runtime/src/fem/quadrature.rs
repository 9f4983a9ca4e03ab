//! Quadrature rules on reference simplices: Gauss–Legendre on [0, 1]; on triangles the
//! symmetric rules of degree 1, 2, 4 (6 points) and 6 (12 points, Dunavant), collapsed
//! Gauss products beyond; on tetrahedra degree 1 and 2 rules, collapsed products beyond.
//! All weights are positive; weights sum to the reference measure (1, 1/2, 1/6).

/// Points and weights on a reference cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    pub points: Vec<Vec<f64>>,
    pub weights: Vec<f64>,
    /// Polynomials up to this degree are integrated exactly.
    pub degree: u32,
}

impl Rule {
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }
}

/// The rule of at least `degree` on the reference simplex of dimension `dim` (0: a point).
pub fn simplex_rule(dim: usize, degree: u32) -> Rule {
    match dim {
        0 => Rule { points: vec![vec![]], weights: vec![1.0], degree: u32::MAX },
        1 => gauss_legendre(degree as usize / 2 + 1),
        2 => triangle(degree),
        _ => tetrahedron(degree),
    }
}

/// A rule of many evenly spread points on the reference simplex of dimension `dim` ≤ 2, for
/// sampling (a pressure profile, the measure of a contact zone) rather than for exactness: the
/// n-point Gauss rule on edges, the centroids of the n² congruent sub-triangles on triangles.
pub fn sampling_rule(dim: usize, n: usize) -> Rule {
    let n = n.max(1);
    match dim {
        0 | 1 => simplex_rule(dim, 2 * n as u32 - 1),
        2 => {
            let (mut points, h) = (Vec::with_capacity(n * n), 1.0 / n as f64);
            for i in 0..n {
                for j in 0..n - i {
                    let (x, y) = (i as f64 * h, j as f64 * h);
                    points.push(vec![x + h / 3.0, y + h / 3.0]);
                    if i + j + 1 < n {
                        points.push(vec![x + 2.0 * h / 3.0, y + 2.0 * h / 3.0]);
                    }
                }
            }
            let weights = vec![0.5 / (n * n) as f64; n * n];
            Rule { points, weights, degree: 1 }
        }
        _ => panic!("sampling rules are for facets (dimension ≤ 2), not dimension {dim}"),
    }
}

/// n-point Gauss–Legendre rule on [0, 1] (exact to degree 2n − 1); nodes by Newton's method on
/// the Legendre polynomial from Chebyshev guesses.
pub fn gauss_legendre(n: usize) -> Rule {
    let mut points = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (p, d) = legendre(n, x);
            dp = d;
            let dx = p / d;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let (_, d) = legendre(n, x);
        dp = if d != 0.0 { d } else { dp };
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        points.push(vec![0.5 * (1.0 - x)]);
        weights.push(0.5 * w);
    }
    // Increasing order of the points.
    points.reverse();
    weights.reverse();
    Rule { points, weights, degree: (2 * n - 1) as u32 }
}

/// P_n(x) and P_n'(x).
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let k = k as f64;
        let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

fn triangle(degree: u32) -> Rule {
    let mut r = Rule { points: Vec::new(), weights: Vec::new(), degree };
    // Orbits of barycentric coordinates with weights normalised to area 1/2.
    let mut s3 = |a: f64, w: f64| {
        let b = 1.0 - 2.0 * a;
        for p in [[a, a], [b, a], [a, b]] {
            r.points.push(p.to_vec());
            r.weights.push(0.5 * w);
        }
    };
    match degree {
        0 | 1 => {
            return Rule { points: vec![vec![1.0 / 3.0, 1.0 / 3.0]], weights: vec![0.5], degree: 1 };
        }
        2 => s3(1.0 / 6.0, 1.0 / 3.0),
        3 | 4 => {
            s3(0.445_948_490_915_964_9, 0.223_381_589_678_011_5);
            s3(0.091_576_213_509_770_74, 0.109_951_743_655_321_9);
            r.degree = 4;
        }
        5 | 6 => {
            s3(0.249_286_745_170_910_4, 0.116_786_275_726_379_4);
            s3(0.063_089_014_491_502_23, 0.050_844_906_370_206_82);
            let (a, b, w) = (0.053_145_049_844_816_95, 0.310_352_451_033_784_4, 0.082_851_075_618_373_58);
            let c = 1.0 - a - b;
            for p in [[a, b], [b, a], [a, c], [c, a], [b, c], [c, b]] {
                r.points.push(p.to_vec());
                r.weights.push(0.5 * w);
            }
            r.degree = 6;
        }
        _ => return collapsed_triangle(degree),
    }
    r
}

/// Duffy-collapsed Gauss product on the triangle: x = a, y = b(1 − a), dx dy = (1 − a) da db.
fn collapsed_triangle(degree: u32) -> Rule {
    let n = (degree as usize + 2).div_ceil(2);
    let g = gauss_legendre(n);
    let mut r = Rule { points: Vec::new(), weights: Vec::new(), degree };
    for (pa, wa) in g.points.iter().zip(&g.weights) {
        for (pb, wb) in g.points.iter().zip(&g.weights) {
            let (a, b) = (pa[0], pb[0]);
            r.points.push(vec![a, b * (1.0 - a)]);
            r.weights.push(wa * wb * (1.0 - a));
        }
    }
    r
}

fn tetrahedron(degree: u32) -> Rule {
    match degree {
        0 | 1 => Rule { points: vec![vec![0.25; 3]], weights: vec![1.0 / 6.0], degree: 1 },
        2 => {
            let a = (5.0 - 5f64.sqrt()) / 20.0;
            let b = (5.0 + 3.0 * 5f64.sqrt()) / 20.0;
            let points = vec![vec![a, a, a], vec![b, a, a], vec![a, b, a], vec![a, a, b]];
            Rule { points, weights: vec![1.0 / 24.0; 4], degree: 2 }
        }
        _ => {
            // x = a, y = b(1 − a), z = c(1 − a)(1 − b); Jacobian (1 − a)²(1 − b).
            let n = (degree as usize + 3).div_ceil(2);
            let g = gauss_legendre(n);
            let mut r = Rule { points: Vec::new(), weights: Vec::new(), degree };
            for (pa, wa) in g.points.iter().zip(&g.weights) {
                for (pb, wb) in g.points.iter().zip(&g.weights) {
                    for (pc, wc) in g.points.iter().zip(&g.weights) {
                        let (a, b, c) = (pa[0], pb[0], pc[0]);
                        r.points.push(vec![a, b * (1.0 - a), c * (1.0 - a) * (1.0 - b)]);
                        r.weights.push(wa * wb * wc * (1.0 - a).powi(2) * (1.0 - b));
                    }
                }
            }
            r
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn factorial(n: u32) -> f64 {
        (1..=n).map(f64::from).product()
    }

    /// ∫ over the reference simplex of Π x_k^{e_k} = Π e_k! / (d + Σ e_k)!.
    fn exact(e: &[u32]) -> f64 {
        e.iter().map(|&k| factorial(k)).product::<f64>() / factorial(e.len() as u32 + e.iter().sum::<u32>())
    }

    fn exponents(dim: usize, max: u32) -> Vec<Vec<u32>> {
        let mut out = vec![vec![]];
        for _ in 0..dim {
            out = out.into_iter().flat_map(|e| (0..=max).map(move |k| [e.clone(), vec![k]].concat())).collect();
        }
        out.into_iter().filter(|e| e.iter().sum::<u32>() <= max).collect()
    }

    #[test]
    fn rules_integrate_monomials_exactly_up_to_their_degree() {
        for dim in 1..=3 {
            for degree in 1..=10 {
                let r = simplex_rule(dim, degree);
                assert!(r.degree >= degree);
                assert!(r.weights.iter().all(|w| *w > 0.0));
                for e in exponents(dim, degree) {
                    let q: f64 = r
                        .points
                        .iter()
                        .zip(&r.weights)
                        .map(|(p, w)| w * p.iter().zip(&e).map(|(x, k)| x.powi(*k as i32)).product::<f64>())
                        .sum();
                    let ex = exact(&e);
                    assert!(
                        (q - ex).abs() < 1e-14 * ex.max(1e-3),
                        "dim {dim} degree {degree} monomial {e:?}: {q} vs {ex}"
                    );
                }
            }
        }
    }

    #[test]
    fn triangle_rules_have_the_published_sizes() {
        assert_eq!(simplex_rule(2, 2).len(), 3);
        assert_eq!(simplex_rule(2, 4).len(), 6);
        assert_eq!(simplex_rule(2, 6).len(), 12);
    }

    #[test]
    fn the_sampling_rule_covers_the_triangle_evenly_and_integrates_linear_functions() {
        for n in [1, 2, 5, 8] {
            let r = sampling_rule(2, n);
            assert_eq!(r.points.len(), n * n);
            assert!(r.points.iter().all(|p| p[0] > 0.0 && p[1] > 0.0 && p[0] + p[1] < 1.0));
            let integral =
                |f: &dyn Fn(&[f64]) -> f64| r.points.iter().zip(&r.weights).map(|(p, w)| w * f(p)).sum::<f64>();
            assert!((integral(&|_| 1.0) - 0.5).abs() < 1e-15);
            assert!((integral(&|p| 3.0 * p[0] - p[1]) - 1.0 / 3.0).abs() < 1e-14);
        }
        assert_eq!(sampling_rule(1, 7).points.len(), 7);
    }
}
