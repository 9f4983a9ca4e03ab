//! Exact rationals over i128, and the way of giving up when they overflow (the simplifier's,
//! the energy identity's).

/// The simplification gave up (rational overflow, or a node that is not scheme arithmetic).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GiveUp;

pub(super) type Res<T> = Result<T, GiveUp>;

/// An exact rational, `d > 0`, in lowest terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Rat {
    pub(super) n: i128,
    pub(super) d: i128,
}

pub(super) fn gcd(a: i128, b: i128) -> i128 {
    let (mut a, mut b) = (a.unsigned_abs(), b.unsigned_abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a as i128
}

impl Rat {
    pub(super) const ZERO: Rat = Rat { n: 0, d: 1 };
    pub(super) const ONE: Rat = Rat { n: 1, d: 1 };

    pub(super) fn new(n: i128, d: i128) -> Res<Rat> {
        if d == 0 {
            return Err(GiveUp);
        }
        let g = gcd(n, d).max(1);
        let (n, d) = (n / g, d / g);
        if d < 0 {
            Ok(Rat { n: n.checked_neg().ok_or(GiveUp)?, d: d.checked_neg().ok_or(GiveUp)? })
        } else {
            Ok(Rat { n, d })
        }
    }

    pub(super) fn int(n: i128) -> Rat {
        Rat { n, d: 1 }
    }

    pub(super) fn is_zero(self) -> bool {
        self.n == 0
    }

    pub(super) fn add(self, o: Rat) -> Res<Rat> {
        let g = gcd(self.d, o.d);
        let (a, b) = (self.d / g, o.d / g);
        let n = self.n.checked_mul(b).and_then(|x| o.n.checked_mul(a).and_then(|y| x.checked_add(y))).ok_or(GiveUp)?;
        let d = self.d.checked_mul(b).ok_or(GiveUp)?;
        Rat::new(n, d)
    }

    pub(super) fn mul(self, o: Rat) -> Res<Rat> {
        // Cross-reduce first to keep the numbers small.
        let g1 = gcd(self.n, o.d).max(1);
        let g2 = gcd(o.n, self.d).max(1);
        let n = (self.n / g1).checked_mul(o.n / g2).ok_or(GiveUp)?;
        let d = (self.d / g2).checked_mul(o.d / g1).ok_or(GiveUp)?;
        Rat::new(n, d)
    }

    pub(super) fn inv(self) -> Res<Rat> {
        Rat::new(self.d, self.n)
    }

    pub(super) fn powi(self, k: i32) -> Res<Rat> {
        let base = if k < 0 { self.inv()? } else { self };
        let mut r = Rat::ONE;
        for _ in 0..k.unsigned_abs() {
            r = r.mul(base)?;
        }
        Ok(r)
    }

    /// −1, 0 or 1 (the derived order compares numerators first: no use for values).
    pub(super) fn signum(self) -> i128 {
        self.n.signum()
    }

    pub(super) fn sub(self, o: Rat) -> Res<Rat> {
        self.add(Rat::new(o.n.checked_neg().ok_or(GiveUp)?, o.d)?)
    }

    pub(super) fn numer(self) -> i128 {
        self.n
    }

    pub(super) fn denom(self) -> i128 {
        self.d
    }

    pub(super) fn to_f64(self) -> f64 {
        self.n as f64 / self.d as f64
    }

    /// `v` as a small rational `p/q` (q ≤ 1024, or a power of ten) whose f64 quotient is `v`
    /// exactly: the constants schemes write (`1/3`, `0.05`, `1e-6`) become exact.
    pub(super) fn from_f64(v: f64) -> Option<Rat> {
        if !v.is_finite() {
            return None;
        }
        let limit = 2f64.powi(62);
        let try_q = |q: i128| {
            let p = (v * q as f64).round();
            (p.abs() < limit && p / q as f64 == v).then(|| Rat::new(p as i128, q).ok()).flatten()
        };
        (1..=1024).chain((4..=18).map(|k| 10i128.pow(k))).find_map(try_q)
    }
}
