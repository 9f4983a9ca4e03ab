//! The sign of a polynomial in a scheme's params over their declared ranges, certified by
//! Bernstein coefficients (every one ≥ 0 on a box: the polynomial is ≥ 0 on it) with boxes
//! halved where they do not decide, and a point of the ranges where it is negative as the
//! witness against. Never claims more than it proved.

use super::super::rational::{Rat, Res};
use super::poly::{DT, Poly, Var};

/// A param's declared range, exactly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub lo: Rat,
    pub lo_closed: bool,
    pub hi: Rat,
    pub hi_closed: bool,
}

impl Interval {
    fn contains(&self, x: Rat) -> Res<bool> {
        let above = x.sub(self.lo)?.signum();
        let below = self.hi.sub(x)?.signum();
        Ok((above > 0 || (above == 0 && self.lo_closed)) && (below > 0 || (below == 0 && self.hi_closed)))
    }
}

/// Where the params range: an interval per param, none where the range is not bounded (or
/// not exactly rational). dt > 0 always.
#[derive(Clone, Debug)]
pub struct Region(pub Vec<Option<Interval>>);

/// What is known of a polynomial's sign over a region.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sign {
    /// Proved ≥ 0 everywhere in the region.
    pub nonnegative: bool,
    /// Proved ≤ 0 everywhere in the region.
    pub nonpositive: bool,
    /// A point of the region where it is < 0 (the params in order, then dt where the sign
    /// depends on it), if one was found.
    pub negative_at: Option<Vec<Rat>>,
}

/// Halvings per box before the sign is left undecided.
const DEPTH: u32 = 8;

impl Region {
    /// The params' declared ranges, exactly where they are finite small rationals.
    pub fn of(ir: &crate::scheme::ir::SchemeIr) -> Region {
        Region(
            ir.params
                .iter()
                .map(|p| {
                    let r = p.range?;
                    Some(Interval {
                        lo: Rat::from_f64(r.lo)?,
                        lo_closed: r.lo_closed,
                        hi: Rat::from_f64(r.hi)?,
                        hi_closed: r.hi_closed,
                    })
                })
                .collect(),
        )
    }

    /// The sign of `p` (in params and dt, dt read only as a monomial factor) over the region.
    pub fn sign(&self, p: &Poly) -> Res<Sign> {
        let vars = p.vars();
        if p.is_zero() {
            return Ok(Sign { nonnegative: true, nonpositive: true, negative_at: None });
        }
        // dt only as a factor dt^k of every term: its sign is the rest's.
        let (monomial, rest) = p.monomial_content();
        let mut boxes = Vec::new();
        for &v in vars.iter().filter(|&&v| v != DT) {
            match self.0.get(v as usize).copied().flatten() {
                Some(i) => boxes.push((v, i)),
                None => return Ok(Sign::default()),
            }
        }
        // dt other than as a factor: no certificate, a witness looked for at dt from 1/100 to
        // 100 (after the params, as one more coordinate).
        if rest.reads(DT) {
            for dt in [Rat::new(1, 100)?, Rat::new(1, 10)?, Rat::ONE, Rat::int(10), Rat::int(100)] {
                if let Some(mut at) = self.search(p, &boxes, dt)?.negative_at {
                    at.push(dt);
                    return Ok(Sign { negative_at: Some(at), ..Sign::default() });
                }
            }
            return Ok(Sign::default());
        }
        // The monomial's params: their sign on the box, folded into the rest's.
        let mut flip = false;
        for (v, e) in monomial.iter().filter(|(v, _)| *v != DT) {
            let i = boxes.iter().find(|(w, _)| w == v).map(|(_, i)| *i).ok_or(super::super::rational::GiveUp)?;
            if e % 2 == 1 && i.lo.signum() < 0 {
                if i.hi.signum() > 0 {
                    // A monomial that changes sign: no certificate, perhaps a witness.
                    return self.search(p, &boxes, Rat::ONE);
                }
                flip = !flip;
            }
        }
        let rest = if flip { rest.neg()? } else { rest };
        let (lo, hi): (Vec<Rat>, Vec<Rat>) = boxes.iter().map(|(_, i)| (i.lo, i.hi)).unzip();
        let vars: Vec<Var> = boxes.iter().map(|(v, _)| *v).collect();
        let mut sign = Sign { nonnegative: true, nonpositive: true, negative_at: None };
        self.decide(&rest, &vars, lo, hi, DEPTH, &mut sign, &boxes)?;
        // p = (−m)·(−rest) with −m ≥ 0: p has the sign of the negated rest; its witnesses are
        // looked for on p itself (below).
        // A witness is one only where p itself is negative (a corner of the rest may sit where
        // the monomial vanishes).
        if let Some(at) = &sign.negative_at {
            let value =
                p.eval_exact(&|v| if v == DT { Rat::ONE } else { at.get(v as usize).copied().unwrap_or(Rat::ZERO) })?;
            if flip || value.signum() >= 0 {
                sign.negative_at = None;
            }
        }
        if sign.negative_at.is_none() && !sign.nonnegative {
            return Ok(Sign { negative_at: self.search(p, &boxes, Rat::ONE)?.negative_at, ..sign });
        }
        Ok(sign)
    }

    /// Bernstein bounds on the box [lo, hi] of `p`, halved while undecided: clears
    /// `nonnegative`/`nonpositive` where a box does not certify them, and sets `negative_at`
    /// at a corner in the region where p < 0.
    #[allow(clippy::too_many_arguments)]
    fn decide(
        &self,
        p: &Poly,
        vars: &[Var],
        lo: Vec<Rat>,
        hi: Vec<Rat>,
        depth: u32,
        sign: &mut Sign,
        boxes: &[(Var, Interval)],
    ) -> Res<()> {
        let (coefficients, corners) = bernstein(p, vars, &lo, &hi)?;
        let all_nonneg = coefficients.iter().all(|c| c.signum() >= 0);
        let all_nonpos = coefficients.iter().all(|c| c.signum() <= 0);
        for (point, value) in &corners {
            if value.signum() < 0 && sign.negative_at.is_none() && self.inside(boxes, point)? {
                sign.negative_at = Some(self.point(boxes, point));
            }
        }
        if all_nonneg && all_nonpos {
            return Ok(());
        }
        if all_nonneg {
            sign.nonpositive = false;
            return Ok(());
        }
        if all_nonpos {
            sign.nonnegative = false;
            return Ok(());
        }
        if depth == 0 || vars.is_empty() {
            sign.nonnegative = false;
            sign.nonpositive = false;
            return Ok(());
        }
        // Halve the widest side.
        let widths: Vec<Rat> = lo.iter().zip(&hi).map(|(l, h)| h.sub(*l)).collect::<Res<_>>()?;
        let k = (0..vars.len()).max_by(|&a, &b| widths[a].sub(widths[b]).map_or(0, Rat::signum).cmp(&0)).unwrap_or(0);
        let mid = lo[k].add(hi[k])?.mul(Rat::new(1, 2)?)?;
        let (mut left_hi, mut right_lo) = (hi.clone(), lo.clone());
        left_hi[k] = mid;
        right_lo[k] = mid;
        self.decide(p, vars, lo, left_hi, depth - 1, sign, boxes)?;
        self.decide(p, vars, right_lo, hi, depth - 1, sign, boxes)
    }

    fn inside(&self, boxes: &[(Var, Interval)], point: &[Rat]) -> Res<bool> {
        for ((_, i), x) in boxes.iter().zip(point) {
            if !i.contains(*x)? {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// A point of the box's variables as one of every param (the others at their range's
    /// middle, or 0).
    fn point(&self, boxes: &[(Var, Interval)], at: &[Rat]) -> Vec<Rat> {
        (0..self.0.len())
            .map(|i| {
                boxes.iter().position(|(v, _)| *v as usize == i).map(|k| at[k]).unwrap_or_else(|| {
                    self.0[i]
                        .and_then(|r| r.lo.add(r.hi).and_then(|s| s.mul(Rat::new(1, 2)?)).ok())
                        .unwrap_or(Rat::ZERO)
                })
            })
            .collect()
    }

    /// A grid over the region (9 points a side for up to 3 params, fewer beyond; open ends
    /// moved in), at `dt`, for a point where p < 0.
    fn search(&self, p: &Poly, boxes: &[(Var, Interval)], dt: Rat) -> Res<Sign> {
        // At most about 4096 points: 9 a side for up to 3 params, fewer beyond.
        let per_side = (4096f64.powf(1.0 / boxes.len().max(1) as f64).floor() as usize).clamp(2, 9);
        let last = per_side as i128 - 1;
        let sides: Vec<Vec<Rat>> = boxes
            .iter()
            .map(|(_, i)| {
                (0..=last)
                    .map(|k| {
                        let k = match k {
                            0 if !i.lo_closed => Rat::new(1, 64 * last),
                            k if k == last && !i.hi_closed => Rat::new(64 * last - 1, 64 * last),
                            k => Rat::new(k, last),
                        }?;
                        i.lo.add(i.hi.sub(i.lo)?.mul(k)?)
                    })
                    .collect::<Res<Vec<Rat>>>()
            })
            .collect::<Res<_>>()?;
        let mut index = vec![0usize; boxes.len()];
        loop {
            let at: Vec<Rat> = index.iter().enumerate().map(|(k, &j)| sides[k][j]).collect();
            let value = p.eval_exact(&|v| {
                if v == DT {
                    return dt;
                }
                boxes.iter().position(|(w, _)| *w == v).map_or(Rat::ZERO, |k| at[k])
            })?;
            if value.signum() < 0 {
                return Ok(Sign { negative_at: Some(self.point(boxes, &at)), ..Sign::default() });
            }
            // The next grid point.
            let mut k = 0;
            loop {
                if k == index.len() {
                    return Ok(Sign::default());
                }
                index[k] += 1;
                if index[k] < per_side {
                    break;
                }
                index[k] = 0;
                k += 1;
            }
        }
    }
}

/// The Bernstein coefficients of `p` over the box [lo, hi] of `vars` (of the degrees p has in
/// each), and the exact values at the box's corners (corner coordinates, value).
#[allow(clippy::type_complexity)]
fn bernstein(p: &Poly, vars: &[Var], lo: &[Rat], hi: &[Rat]) -> Res<(Vec<Rat>, Vec<(Vec<Rat>, Rat)>)> {
    // q(s) = p(lo + (hi − lo)·s) on the unit box.
    let mut q = p.clone();
    for (k, &v) in vars.iter().enumerate() {
        let by = Poly::constant(lo[k]).add(&Poly::var(v).scale(hi[k].sub(lo[k])?)?)?;
        q = q.substitute(v, &by)?;
    }
    let degrees: Vec<u32> = vars.iter().map(|&v| p.degree_in(v)).collect();
    let coefficient = |j: &[u32]| -> Rat {
        q.terms()
            .find(|(m, _)| {
                vars.iter().zip(j).all(|(&v, &e)| m.iter().find(|(w, _)| *w == v).map_or(0, |&(_, f)| f) == e)
                    && m.iter().all(|(w, _)| vars.contains(w))
            })
            .map_or(Rat::ZERO, |(_, c)| c)
    };
    let indices = |upper: &[u32]| -> Vec<Vec<u32>> {
        let mut all = vec![Vec::new()];
        for &d in upper {
            all = all.into_iter().flat_map(|i: Vec<u32>| (0..=d).map(move |k| [i.clone(), vec![k]].concat())).collect();
        }
        all
    };
    let binomial = |n: u32, k: u32| -> Res<Rat> {
        let mut b = 1i128;
        for i in 0..k {
            b = b.checked_mul((n - i) as i128).ok_or(super::super::rational::GiveUp)? / (i + 1) as i128;
        }
        Ok(Rat::int(b))
    };
    // Beyond about 4096 coefficients a box is left undecided (its cost grows as their square).
    if degrees.iter().map(|&d| d as usize + 1).product::<usize>() > 4096 {
        return Err(super::super::rational::GiveUp);
    }
    let mut coefficients = Vec::new();
    let mut corners = Vec::new();
    for i in indices(&degrees) {
        let mut b = Rat::ZERO;
        for j in indices(&i) {
            let mut w = coefficient(&j);
            if w.is_zero() {
                continue;
            }
            for (k, (&ik, &jk)) in i.iter().zip(&j).enumerate() {
                w = w.mul(binomial(ik, jk)?)?.mul(binomial(degrees[k], jk)?.inv()?)?;
            }
            b = b.add(w)?;
        }
        if i.iter().zip(&degrees).all(|(&ik, &d)| ik == 0 || ik == d) {
            let at = i.iter().enumerate().map(|(k, &ik)| if ik == 0 { lo[k] } else { hi[k] }).collect();
            corners.push((at, b));
        }
        coefficients.push(b);
    }
    Ok((coefficients, corners))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(n: i128, d: i128) -> Rat {
        Rat::new(n, d).unwrap()
    }

    fn newmark_region() -> Region {
        Region(vec![
            Some(Interval { lo: r(0, 1), lo_closed: false, hi: r(1, 2), hi_closed: true }),
            Some(Interval { lo: r(1, 2), lo_closed: true, hi: r(1, 1), hi_closed: true }),
        ])
    }

    #[test]
    fn a_linear_factor_is_decided_at_the_corners() {
        let (beta, gam) = (Poly::var(0), Poly::var(1));
        // 2γ − 1 ≥ 0 on γ ∈ [½, 1].
        let s = newmark_region().sign(&gam.scale(Rat::int(2)).unwrap().sub(&Poly::one()).unwrap()).unwrap();
        assert!(s.nonnegative && !s.nonpositive && s.negative_at.is_none());
        // 2β − γ changes sign: a witness in the ranges (β = 0 is not in them).
        let s = newmark_region().sign(&beta.scale(Rat::int(2)).unwrap().sub(&gam).unwrap()).unwrap();
        assert!(!s.nonnegative && !s.nonpositive);
        let at = s.negative_at.expect("a witness");
        assert!(at[0].signum() > 0);
        assert!(at[0].mul(Rat::int(2)).unwrap().sub(at[1]).unwrap().signum() < 0);
    }

    #[test]
    fn a_square_is_certified_after_halving() {
        // (α − ¼)² + 1/100 on [0, ⅓]: positive, though its Bernstein coefficients on the whole
        // box need not all be; −(…) is certified ≤ 0 with a witness.
        let alpha = Poly::var(0);
        let p = alpha.sub(&Poly::constant(r(1, 4))).unwrap().pow(2).unwrap().add(&Poly::constant(r(1, 100))).unwrap();
        let region = Region(vec![Some(Interval { lo: r(0, 1), lo_closed: true, hi: r(1, 3), hi_closed: true })]);
        let s = region.sign(&p).unwrap();
        assert!(s.nonnegative && s.negative_at.is_none());
        let s = region.sign(&p.neg().unwrap()).unwrap();
        assert!(s.nonpositive && !s.nonnegative && s.negative_at.is_some());
        // dt² (2γ − 1): dt's factor does not change the sign.
        let q = Poly::var(DT)
            .pow(2)
            .unwrap()
            .mul(&Poly::var(1).scale(Rat::int(2)).unwrap().sub(&Poly::one()).unwrap())
            .unwrap();
        assert!(newmark_region().sign(&q).unwrap().nonnegative);
    }

    #[test]
    fn a_sign_that_depends_on_dt_is_refuted_at_a_step() {
        // 2dt − 1 < 0 for dt < 1/2: the witness's last coordinate is that dt.
        let p = Poly::var(DT).scale(Rat::int(2)).unwrap().sub(&Poly::one()).unwrap();
        let s = newmark_region().sign(&p).unwrap();
        assert!(!s.nonnegative && !s.nonpositive);
        let at = s.negative_at.expect("a witness");
        assert_eq!(at.len(), 3);
        assert!(at[2].mul(Rat::int(2)).unwrap().sub(Rat::ONE).unwrap().signum() < 0);
    }
}
