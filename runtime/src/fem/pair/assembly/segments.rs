//! Integration by segments (2D): where an own facet is cut, and the tangent's part through the
//! cuts' motion.

use super::*;

/// A point s of own facet `facet` where it is cut: the integrand jumps there (the facing
/// point changes facet), and the cut moves with the bodies by the rule that placed it.
pub(super) struct Cut {
    facet: u32,
    s: f64,
    /// The facing point of x(s) on the facing facet before the cut and after it (none: facing
    /// nothing on that side).
    before: Option<Facing>,
    after: Option<Facing>,
    rule: CutRule,
}

pub(super) enum CutRule {
    /// (x(s) − p)·t = 0: x(s) crosses the line through a facing facet's end p normal to it.
    Line(crate::fem::facing::End),
    /// (x − p)·(o_A − o_B) = 0: both facets' closest point is their common end p, and the
    /// point faces the one it overshoots least; o = ±t/|t| their tangents there, pointing out
    /// of each (the sign: +1 at a facet's second end).
    Bisector { a: crate::fem::facing::End, b: crate::fem::facing::End, signs: [f64; 2] },
}

impl PairForm<'_> {
    /// Adds to `m` the tangent's part through the cuts' motion (by segments): at each cut s,
    /// the integrand's jump there (before minus after) times the cut's rate
    /// ds/du = −(∂φ/∂u)/(∂φ/∂s), φ = 0 the rule that placed it. The pair of nodes the pattern
    /// lacked, if any.
    pub(super) fn add_cuts(
        &self,
        mesh: &Mesh,
        cuts: &[Cut],
        fields: &[&[f64]],
        t: f64,
        m: &mut Matrix,
    ) -> Option<(u32, u32)> {
        let d = mesh.dim();
        let moving = fields[CONFIGURATION];
        let pattern = m.pattern.clone();
        let mut missing = None;
        let mut r = vec![0.0; layout::residual(d)];
        let dot = |a: &[f64], b: &[f64]| (0..d).map(|k| a[k] * b[k]).sum::<f64>();
        for cut in cuts {
            let f = self.own[cut.facet as usize];
            // The basis at the cut, weighted per unit of s.
            let (xi, scale) = mesh.kind.facet_point(f.local as usize, &[cut.s]);
            let q = Tabulated { weight: scale, phi: mesh.kind.basis(&xi), dref: mesh.kind.basis_gradients(&xi) };
            let ref_normal = &self.rule[f.local as usize].1;
            let mut jump: Vec<(u32, usize, f64)> = Vec::new();
            for (facing, sign) in [(&cut.before, 1.0), (&cut.after, -1.0)] {
                let Some(facing) = facing else { continue };
                let e = self.element(mesh, f, &q, ref_normal, facing, fields, t, false);
                r.fill(0.0);
                if self.kernel.residual_at(self.region, &e.point, &mut r) {
                    Self::contract(&e, &r, d, |a, k, v| jump.push((e.nodes[a], k, sign * v)));
                }
            }
            if jump.iter().all(|j| j.2 == 0.0) {
                continue;
            }
            // x(s) and x'(s) on the configuration.
            let cell = mesh.cell(f.cell as usize);
            let edge = &self.edges[f.local as usize][0];
            let (mut x, mut dx) = ([0.0; MAX_DIM], [0.0; MAX_DIM]);
            for (a, &n) in cell.iter().enumerate() {
                let along: f64 = (0..d).map(|c| q.dref[a][c] * edge[c]).sum();
                for k in 0..d {
                    let position = mesh.node(n as usize)[k] + moving.get(n as usize * d + k).copied().unwrap_or(0.0);
                    x[k] += q.phi[a] * position;
                    dx[k] += along * position;
                }
            }
            // ∂φ/∂u per (node, component), and ∂φ/∂s.
            let mut grad: Vec<(u32, usize, f64)> = Vec::new();
            let rate_s = match &cut.rule {
                CutRule::Line(end) => {
                    let (p, tangent) = (&end.point, &end.tangent);
                    for (a, &n) in cell.iter().enumerate() {
                        grad.extend((0..d).map(|k| (n, k, q.phi[a] * tangent[k])));
                    }
                    for k in 0..d {
                        grad.push((end.node, k, -tangent[k]));
                        grad.extend(end.weights.iter().map(|&(n, w)| (n, k, (x[k] - p[k]) * w)));
                    }
                    dot(&dx, tangent)
                }
                CutRule::Bisector { a, b, signs } => {
                    let p = &a.point;
                    let unit = |t: &[f64; 3]| {
                        let size = dot(t, t).sqrt();
                        (std::array::from_fn::<f64, 3, _>(|k| t[k] / size), size)
                    };
                    let ((ta, la), (tb, lb)) = (unit(&a.tangent), unit(&b.tangent));
                    let o: [f64; 3] = std::array::from_fn(|k| signs[0] * ta[k] - signs[1] * tb[k]);
                    let off: [f64; 3] = std::array::from_fn(|k| if k < d { x[k] - p[k] } else { 0.0 });
                    for (c, &n) in cell.iter().enumerate() {
                        grad.extend((0..d).map(|k| (n, k, q.phi[c] * o[k])));
                    }
                    for k in 0..d {
                        grad.push((a.node, k, -o[k]));
                    }
                    // δo = ±(I − t̂t̂ᵀ) δt/|t|, δt = Σ w_b δu_b.
                    for (end, t, size, sign) in [(a, ta, la, signs[0]), (b, tb, lb, -signs[1])] {
                        let along = dot(&off, &t);
                        for &(n, w) in &end.weights {
                            grad.extend((0..d).map(|k| (n, k, sign / size * (off[k] - t[k] * along) * w)));
                        }
                    }
                    dot(&dx, &o)
                }
            };
            let size_s = grad.iter().map(|g| g.2.abs()).fold(0.0, f64::max) * dot(&dx, &dx).sqrt();
            if rate_s.abs() <= 1e-12 * size_s {
                continue;
            }
            let mut nodes: Vec<u32> = jump.iter().map(|j| j.0).chain(grad.iter().map(|g| g.0)).collect();
            nodes.sort_unstable();
            nodes.dedup();
            let at = |n: u32| nodes.binary_search(&n).unwrap_or_default();
            let size = nodes.len() * d;
            let mut ke = vec![0.0; size * size];
            for &(row_node, row_k, jv) in &jump {
                let row = at(row_node) * d + row_k;
                for &(col_node, col_k, gv) in &grad {
                    ke[row * size + at(col_node) * d + col_k] -= jv * gv / rate_s;
                }
            }
            if let Err(pair) = pattern.scatter_nodes(&nodes, &ke, |pos, v| m.values[pos] += v) {
                missing = Some(pair);
            }
        }
        missing
    }

    /// The pieces [a, b] of own facet `f` (the `index`-th; 2D, s ∈ [0, 1] along it) between the points where
    /// the integrand has a kink or a jump, within the reach: where x(s), on the configuration,
    /// crosses the normal line through a facing facet's end (its facing point reaches the end)
    /// or the line where the facing point passes from one facet to the next; and the cuts,
    /// with what each faces on either side and the rule that places it. The facet on the
    /// configuration is x(s) = x0 + c1 s + c2 s², a straight (P1) or quadratic (P2) curve, so
    /// each line cuts it at the roots of a quadratic. On P2 the facets curve, and the point
    /// where two facets that both face x are equally far lies off that line by the gap times
    /// the curvature: the cut there is the line's.
    pub(super) fn pieces(
        &self,
        index: u32,
        f: Facet,
        mesh: &Mesh,
        position: &dyn Fn(&[f64]) -> [f64; MAX_DIM],
        surface: &Surface,
    ) -> (Vec<(f64, f64)>, Vec<Cut>) {
        let at = |s: f64| position(&mesh.kind.basis(&mesh.kind.facet_point(f.local as usize, &[s]).0));
        let (x0, xm, x1) = (at(0.0), at(0.5), at(1.0));
        let c1: [f64; 2] = std::array::from_fn(|r| -3.0 * x0[r] + 4.0 * xm[r] - x1[r]);
        let c2: [f64; 2] = std::array::from_fn(|r| 2.0 * x0[r] - 4.0 * xm[r] + 2.0 * x1[r]);
        let x = |s: f64| -> [f64; 2] { std::array::from_fn(|r| x0[r] + s * (c1[r] + s * c2[r])) };
        // The curve lies in the box of its Bézier control points x0, x1 and 2 xm − (x0 + x1)/2.
        let control = |r: usize| [x0[r], x1[r], 2.0 * xm[r] - 0.5 * (x0[r] + x1[r])];
        let lower = std::array::from_fn(|r| {
            if r < 2 { control(r).into_iter().fold(f64::INFINITY, f64::min) - self.reach } else { 0.0 }
        });
        let upper = std::array::from_fn(|r| {
            if r < 2 { control(r).into_iter().fold(f64::NEG_INFINITY, f64::max) + self.reach } else { 0.0 }
        });
        // Cuts closer than this to an end or to each other (in s) make no piece.
        const APART: f64 = 1e-10;
        // The facing facets' ends near the facet, by node. An end two facets share is where
        // the facing point passes from one to the other, on the line through it along
        // o_A − o_B (o = ±t/|t| each facet's tangent there, pointing out of it), whether the
        // surface turns away (the point overshoots both, and faces the one it overshoots
        // least) or towards it (the point faces both, and the nearer: on P1 the same line).
        let mut found: Vec<(crate::fem::facing::End, f64)> = surface
            .within(lower, upper)
            .into_iter()
            .flat_map(|k| [(surface.end(k, 0), -1.0), (surface.end(k, 1), 1.0)])
            .collect();
        found.sort_by_key(|(e, _)| e.node);
        let unit = |t: &[f64; 3]| {
            let size = t[0].hypot(t[1]);
            [t[0] / size, t[1] / size]
        };
        let mut cuts: Vec<(f64, CutRule)> = Vec::new();
        let mut cut_along = |p: [f64; 3], o: [f64; 2], rule: &dyn Fn() -> CutRule| {
            let dot = |a: [f64; 2]| a[0] * o[0] + a[1] * o[1];
            let (a, b, c) = (dot(c2), dot(c1), dot([x0[0] - p[0], x0[1] - p[1]]));
            for s in unit_roots(a, b, c) {
                let y = x(s);
                let near = (y[0] - p[0]).hypot(y[1] - p[1]) <= self.reach;
                if near && s > APART && s < 1.0 - APART {
                    cuts.push((s, rule()));
                }
            }
        };
        for group in found.chunk_by(|a, b| a.0.node == b.0.node) {
            // Each end's normal line: there the facing point reaches the end and stops (a kink
            // of the integrand, which a rule across it would miss).
            for (e, _) in group {
                cut_along(e.point, [e.tangent[0], e.tangent[1]], &|| CutRule::Line(e.clone()));
            }
            if let [(a, sa), (b, sb)] = group {
                let (ta, tb) = (unit(&a.tangent), unit(&b.tangent));
                let o = [sa * ta[0] - sb * tb[0], sa * ta[1] - sb * tb[1]];
                let rule = || CutRule::Bisector { a: a.clone(), b: b.clone(), signs: [*sa, *sb] };
                cut_along(a.point, o, &rule);
            }
        }
        cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
        cuts.dedup_by(|a, b| (a.0 - b.0).abs() < APART);
        let mut ends = vec![0.0];
        ends.extend(cuts.iter().map(|c| c.0));
        ends.push(1.0);
        let facet_at = |s: f64| {
            let asked = Instant::now();
            let facing = surface.nearest(&x(s), self.reach).map(|b| b.facet);
            self.meter.queried(asked);
            facing
        };
        let pieces = ends.windows(2).map(|w| (w[0], w[1])).collect();
        // What each cut's point faces on either side, projected onto the facet found there.
        let sides = |s: f64| {
            let y = x(s);
            let on = |t: f64| {
                let facet = facet_at(t)?;
                Some(surface.project(facet, &y)).filter(|b| !b.beyond)
            };
            (on(s - APART), on(s + APART))
        };
        let placed = cuts
            .into_iter()
            .map(|(s, rule)| {
                let (before, after) = sides(s);
                Cut { facet: index, s, before, after, rule }
            })
            .collect();
        (pieces, placed)
    }
}

/// The roots in [0, 1] of a s² + b s + c (a straight facet's a is round-off: the root of
/// b s + c then).
fn unit_roots(a: f64, b: f64, c: f64) -> Vec<f64> {
    let roots = if a.abs() <= 1e-12 * (b.abs() + c.abs()) {
        if b == 0.0 { vec![] } else { vec![-c / b] }
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            vec![]
        } else {
            // The stable pair: q = −(b + sign(b) √disc)/2, roots q/a and c/q.
            let q = -0.5 * (b + b.signum() * disc.sqrt());
            if q == 0.0 { vec![0.0] } else { vec![q / a, c / q] }
        }
    };
    roots.into_iter().filter(|s| (0.0..=1.0).contains(s)).collect()
}
