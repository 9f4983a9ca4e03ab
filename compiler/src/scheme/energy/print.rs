//! `emit --stage energy`: a scheme's identity in its own names, what it proves over the
//! params' ranges, and what it proves at the defaults (the claim's check).

use std::fmt::Write;

use super::classify::{Block, Identity, Proof, Square, sign_over};
use super::names::{Levels, cleared};
use super::ratfn::RatFn;
use super::sign::{Interval, Region};
use super::window::Lin;
use crate::check::EnergyLaw;
use crate::scheme::ir::SchemeIr;

/// The work of the residuals tested with one weight, through one slot: (weight, slot, items
/// as coefficient and application).
type Group = (usize, String, Vec<(RatFn, String)>);

/// The identity of `ir`, or why there is none (one line).
pub fn print(ir: &SchemeIr) -> Result<String, String> {
    let identity = match Identity::derive(ir) {
        Ok(i) => i,
        Err(e) => return Err(super::why(ir, &e)),
    };
    Ok(Printer::new(ir, &identity).print())
}

/// A scheme's identity in its own names.
pub struct Printer<'a> {
    ir: &'a SchemeIr,
    id: &'a Identity,
    levels: Levels,
    region: Region,
}

impl<'a> Printer<'a> {
    pub fn new(ir: &'a SchemeIr, id: &'a Identity) -> Printer<'a> {
        Printer { ir, id, levels: Levels::new(ir, &id.ansatz.window), region: Region::of(ir) }
    }

    /// A coefficient in the scheme's names.
    pub fn r(&self, r: &RatFn) -> String {
        self.levels.style.ratfn(r)
    }

    fn c(&self, r: &RatFn) -> String {
        self.levels.style.coefficient(r)
    }

    fn print(&self) -> String {
        let (ir, id) = (self.ir, self.id);
        let mut out = String::new();
        let params: Vec<String> = ir.params.iter().map(|p| format!("{} = {}", p.name, p.default)).collect();
        let _ = writeln!(out, "scheme {}({}): the energy identity of one step", ir.name, params.join(", "));
        let tested: Vec<String> = id.ansatz.residuals.iter().map(|r| self.residual_name(r.stage)).collect();
        let _ = writeln!(out, "  residuals tested  {}", tested.join("; "));
        let _ = writeln!(out, "  kept energy       Ẽ = {}", self.kept());
        let _ = writeln!(out, "  identity          Ẽ' - Ẽ = W - D");
        for (i, line) in self.work().iter().enumerate() {
            let lead = if i == 0 { "  work              W = " } else { "                      " };
            let _ = writeln!(out, "{lead}{line}");
        }
        let _ = writeln!(out, "  dissipation       D = {}", self.dissipation());
        for line in self.legend() {
            let _ = writeln!(out, "                    {line}");
        }
        for line in self.over_ranges() {
            let _ = writeln!(out, "  {line}");
        }
        for line in self.at_defaults() {
            let _ = writeln!(out, "  {line}");
        }
        out
    }

    /// Whether `r` is negative at the defaults (dt = 1).
    fn below_zero(&self, r: &RatFn) -> bool {
        r.eval(&self.levels.style.at, 1.0, 0.0) < 0.0
    }

    /// Whether `r` is written with a minus in front: its sign is shown outside.
    fn negative(&self, r: &RatFn) -> bool {
        self.levels.style.negative(r)
    }

    fn state(&self, i: usize) -> &str {
        &self.ir.states[i]
    }

    fn velocity(&self) -> &str {
        self.ir.states.iter().find(|s| *s == "v").map_or("v", |s| s.as_str())
    }

    fn acceleration(&self) -> Option<&str> {
        self.ir.initial.as_ref().map(|i| self.state(i.state))
    }

    fn residual_name(&self, stage: Option<usize>) -> String {
        match stage {
            None => format!("{} at t (the previous step's, at this one's start)", self.last_stage()),
            Some(k) => {
                let w = &self.id.ansatz.window;
                let (stage, back) = if k < w.offset { (k, " (the previous step's)") } else { (k - w.offset, "") };
                let name = self.ir.stages.get(stage).map_or("?", |s| s.name.as_str());
                format!("{name} at {}{back}", self.r(&w.times[k]))
            }
        }
    }

    fn last_stage(&self) -> &str {
        self.ir.stages.last().map_or("the step", |s| s.name.as_str())
    }

    fn kept(&self) -> String {
        let (id, u, v) = (self.id, self.state(0), self.velocity());
        let hat = if id.weight.is_some() { "\u{302}" } else { "" };
        let mut text = format!("½‖{v}{hat}‖²_M");
        if id.elastic {
            text.push_str(&format!(" + ½‖{u}{hat}‖²_K"));
        }
        let mut add = |q: &RatFn, what: String| {
            let c = self.c(q);
            match c.strip_prefix('-') {
                Some(m) => text.push_str(&format!(" - {m}·{what}")),
                None => text.push_str(&format!(" + {c}·{what}")),
            }
        };
        if let (Some(q), Some(a)) = (&id.acceleration, self.acceleration()) {
            add(q, format!("½dt²‖{a}{hat}‖²_M"));
        }
        if let Some(q) = &id.step_before {
            add(q, format!("½‖{u} - {u}⁻‖²_K"));
        }
        if let Some(theta) = &id.weight {
            text.push_str(&format!(
                ", x{hat} = (1 - θ)·x + θ·x⁻ with θ = {} (the residual's weight of its inertia)",
                self.r(theta)
            ));
        }
        if !id.elastic {
            text.push_str("  (the stiffness is a force of the scheme's own slot: its work is in W)");
        }
        text
    }

    /// The multipliers of each residual over the increments, solved.
    fn nu(&self, r: &super::engine::Tested) -> Vec<RatFn> {
        r.nu.iter().map(|&k| self.id.ansatz.solved[k].as_ref().map_or(RatFn::zero(), |u| u.c0.clone())).collect()
    }

    fn increment_name(&self, j: usize) -> String {
        let l = &self.id.ansatz.levels;
        format!("{} - {}", self.levels.vector(&l[j + 1]), self.levels.vector(&l[j]))
    }

    /// The test vectors: one per residual, grouped where proportional; a single increment is
    /// named as such, several as w1, w2, … (see [`Printer::legend`]).
    fn weights(&self) -> (Vec<Vec<RatFn>>, Vec<(usize, RatFn)>) {
        let mut bases: Vec<Vec<RatFn>> = Vec::new();
        let mut of = Vec::new();
        for r in &self.id.ansatz.residuals {
            let nu = self.nu(r);
            let found = bases.iter().enumerate().find_map(|(b, base)| proportional(&nu, base).map(|c| (b, c)));
            match found {
                Some(x) => of.push(x),
                None if nu.iter().all(RatFn::is_zero) => of.push((usize::MAX, RatFn::zero())),
                None => {
                    // A single increment is the test vector itself, its multiplier the residual's;
                    // several are cleared to coprime polynomial coefficients.
                    let scale = match nonzero(&nu)[..] {
                        [j] => nu[j].inv().unwrap_or_else(|_| RatFn::one()),
                        _ => {
                            let parts: Vec<(RatFn, String)> = nu.iter().map(|c| (c.clone(), String::new())).collect();
                            let refs: Vec<&(RatFn, String)> = parts.iter().filter(|(c, _)| !c.is_zero()).collect();
                            super::names::normalizer(&refs, &self.levels.style).unwrap_or_else(|_| RatFn::one())
                        }
                    };
                    let base = nu.iter().map(|c| c.mul(&scale).unwrap_or_else(|_| c.clone())).collect();
                    bases.push(base);
                    of.push((bases.len() - 1, scale.inv().unwrap_or_else(|_| RatFn::one())));
                }
            }
        }
        (bases, of)
    }

    fn weight_name(&self, bases: &[Vec<RatFn>], b: usize) -> String {
        match nonzero(&bases[b])[..] {
            [j] if bases.len() == 1 || bases[b][j].as_constant().is_some() => {
                let c = &bases[b][j];
                let name = format!("({})", self.increment_name(j));
                if c.as_constant() == Some(super::super::rational::Rat::ONE) {
                    name
                } else {
                    format!("{}*{name}", self.c(c))
                }
            }
            _ => format!("w{}", b + 1),
        }
    }

    /// The test vectors and the work through each (test vector, slot): a named test vector
    /// (w1, …) carries the common factor of its items, so that they are coprime polynomials.
    fn groups(&self) -> (Vec<Vec<RatFn>>, Vec<Group>) {
        let (mut bases, of) = self.weights();
        // Per weight and slot, the items: coefficient, argument text.
        let mut groups: Vec<Group> = Vec::new();
        for (r, (b, c)) in self.id.ansatz.residuals.iter().zip(&of) {
            let b = *b;
            if b == usize::MAX {
                continue;
            }
            for t in r.terms.iter().filter(|t| t.form != "mass" && t.form != "stiffness") {
                let slot = self.ir.slots.iter().find(|s| s.name == t.form);
                let args = if slot.is_some_and(|s| s.fields == 0) {
                    self.r(&t.time)
                } else {
                    t.args.iter().map(|a| self.levels.vector(a)).collect::<Vec<_>>().join(", ")
                };
                let item = format!("{}({args})", t.form);
                // Moved to the right: −coef.
                let Ok(k) = c.mul(&t.coef).and_then(|x| x.neg()) else { continue };
                let g = match groups.iter().position(|(gb, form, _)| *gb == b && *form == t.form) {
                    Some(g) => g,
                    None => {
                        groups.push((b, t.form.clone(), Vec::new()));
                        groups.len() - 1
                    }
                };
                let items = &mut groups[g].2;
                match items.iter_mut().find(|(_, i)| *i == item) {
                    Some((sum, _)) => *sum = sum.add(&k).unwrap_or_else(|_| sum.clone()),
                    None => items.push((k, item)),
                }
            }
        }
        for (b, base) in bases.iter_mut().enumerate() {
            if nonzero(base).len() < 2 {
                continue;
            }
            let items: Vec<&(RatFn, String)> =
                groups.iter().filter(|g| g.0 == b).flat_map(|g| &g.2).filter(|(c, _)| !c.is_zero()).collect();
            let Ok(s) = super::names::normalizer(&items, &self.levels.style) else { continue };
            // Signed so that the work of the loads (a slot applied to a time alone) comes in
            // with a positive first coefficient, or else the test vector's first is positive.
            let load = groups
                .iter()
                .filter(|g| g.0 == b)
                .find(|g| self.ir.slots.iter().any(|u| u.name == g.1 && u.fields == 0));
            let s = match load.and_then(|g| g.2.iter().find(|(c, _)| !c.is_zero())) {
                Some((c, _)) if self.below_zero(&c.mul(&s).unwrap_or_else(|_| c.clone())) => s.neg().unwrap_or(s),
                Some(_) => s,
                None => {
                    let first = base.iter().find(|c| !c.is_zero()).cloned().unwrap_or_else(RatFn::one);
                    match first.div(&s) {
                        Ok(f) if self.below_zero(&f) => s.neg().unwrap_or(s),
                        _ => s,
                    }
                }
            };
            let Ok(inv) = s.inv() else { continue };
            for g in groups.iter_mut().filter(|g| g.0 == b) {
                for (c, _) in g.2.iter_mut() {
                    *c = c.mul(&s).unwrap_or_else(|_| c.clone());
                }
            }
            for c in base.iter_mut() {
                *c = c.mul(&inv).unwrap_or_else(|_| c.clone());
            }
        }
        (bases, groups)
    }

    fn work(&self) -> Vec<String> {
        let (bases, groups) = self.groups();
        let mut lines = Vec::new();
        for (i, (b, _, items)) in groups.iter().enumerate() {
            let items: Vec<&(RatFn, String)> = items.iter().filter(|(c, _)| !c.is_zero()).collect();
            if items.is_empty() {
                continue;
            }
            // The bracket's sign out front when its coefficients sum to a negative value at the
            // defaults (a contact force's work against the motion), each item's where it is
            // written with a minus.
            let defaults: Vec<f64> = self.ir.params.iter().map(|p| p.default).collect();
            let negative = items.iter().map(|(c, _)| c.eval(&defaults, 1.0, 0.0)).sum::<f64>() < 0.0;
            let mut inside = String::new();
            for (k, (c, item)) in items.iter().enumerate() {
                let c = if negative { c.neg().unwrap_or_else(|_| c.clone()) } else { c.clone() };
                let minus = self.negative(&c);
                let c = if minus { c.neg().unwrap_or(c) } else { c };
                let magnitude = self.c(&c);
                let term = if magnitude == "1" { item.clone() } else { format!("{magnitude}·{item}") };
                let sep = match (k, minus) {
                    (0, false) => "",
                    (0, true) => "-",
                    (_, false) => " + ",
                    (_, true) => " - ",
                };
                let _ = write!(inside, "{sep}{term}");
            }
            let weight = self.weight_name(&bases, *b);
            let bracket = if items.len() > 1 { format!("[{inside}]") } else { inside };
            let sign = match (i, negative) {
                (0, false) => "",
                (0, true) => "-",
                (_, false) => "+ ",
                (_, true) => "- ",
            };
            lines.push(format!("{sign}{weight}·{bracket}"));
        }
        if lines.is_empty() {
            lines.push("0".into());
        }
        lines
    }

    /// The chain of levels a block's squares are named by: the displacement levels for K, the
    /// mass terms' arguments in the residuals' order for M.
    fn chain(&self, block: Block) -> Vec<Lin> {
        match block {
            Block::Stiffness => self.id.ansatz.levels.clone(),
            Block::Mass => {
                // The acceleration's (else the velocity's) previous and start levels first,
                // where the window has them, then the mass terms' arguments, then its end.
                let w = &self.id.ansatz.window;
                let state = match &self.ir.initial {
                    Some(i) => i.state,
                    None => self.ir.states.iter().position(|s| s == "v").unwrap_or(0),
                };
                let before = w
                    .free
                    .iter()
                    .position(|f| *f == super::window::Free::Previous(state))
                    .map(|v| Lin::unit(w.free.len(), v));
                let mut chain: Vec<Lin> = before.into_iter().chain([w.start[state].clone()]).collect();
                for r in &self.id.ansatz.residuals {
                    for t in r.terms.iter().filter(|t| t.form == "mass") {
                        if let [a] = t.args.as_slice()
                            && !chain.contains(a)
                        {
                            chain.push(a.clone());
                        }
                    }
                }
                let end = super::engine::end_level(self.ir, w, state);
                if !chain.contains(&end) {
                    chain.push(end);
                }
                chain
            }
        }
    }

    /// The chain's levels that a square's vector reads, in order: an increment is named by
    /// consecutive levels the vector needs, levels it does not are skipped.
    fn chain_for(&self, s: &Square) -> Vec<Lin> {
        let mut chain = self.chain(s.block);
        // Drop an entry while the vector stays a combination of the increments left: the
        // combinations first, the named levels after.
        for named in [false, true] {
            let mut k = 0;
            while k < chain.len() && chain.len() > 2 {
                let mut fewer = chain.clone();
                fewer.remove(k);
                let keep = self.levels.name(&chain[k]).is_some() != named;
                if !keep && super::forms::solve(&s.vector, &increments(&fewer)).ok().flatten().is_some() {
                    chain = fewer;
                } else {
                    k += 1;
                }
            }
        }
        chain
    }

    /// A square as coefficient·‖combination of increments‖²_B.
    fn square(&self, s: &Square) -> (RatFn, String) {
        let chain = self.chain_for(s);
        let named = super::forms::solve(&s.vector, &increments(&chain)).ok().flatten();
        let (text, scale) = match named {
            Some(c) => {
                let parts: Vec<(RatFn, String)> = c
                    .into_iter()
                    .enumerate()
                    .map(|(j, c)| {
                        (c, format!("{} - {}", self.levels.vector(&chain[j + 1]), self.levels.vector(&chain[j])))
                    })
                    .collect();
                // A square is even: its vector is written with a positive first term.
                let (text, scale) = cleared(&parts, &self.levels.style);
                if text.starts_with('-') {
                    let negated: Vec<(RatFn, String)> =
                        parts.iter().map(|(c, n)| (c.neg().unwrap_or_else(|_| c.clone()), n.clone())).collect();
                    cleared(&negated, &self.levels.style)
                } else {
                    (text, scale)
                }
            }
            None => (self.levels.vector(&s.vector), RatFn::one()),
        };
        let coef = s.coef.div(&scale.powi(2).unwrap_or_else(|_| RatFn::one())).unwrap_or_else(|_| s.coef.clone());
        (coef, format!("‖{text}‖²_{}", s.block.letter()))
    }

    fn dissipation(&self) -> String {
        let d = &self.id.dissipation;
        if let Some((block, p, q)) = d.cross {
            let n = &self.levels.free;
            return format!(
                "indefinite: its part on {} pairs {} with {} and has no square of {}",
                block.letter(),
                n[p],
                n[q],
                n[p]
            );
        }
        let mut out = String::new();
        for (i, s) in d.squares.iter().enumerate() {
            let text = self.described(s);
            match (i, text.strip_prefix('-')) {
                (0, _) => out.push_str(&text),
                (_, Some(rest)) => out.push_str(&format!(" - {rest}")),
                (_, None) => out.push_str(&format!(" + {text}")),
            }
        }
        if out.is_empty() { "0".into() } else { out }
    }

    fn legend(&self) -> Vec<String> {
        let (bases, _) = self.groups();
        let mut out = Vec::new();
        for (b, base) in bases.iter().enumerate() {
            let name = self.weight_name(&bases, b);
            if name.starts_with('w') {
                let parts: Vec<(RatFn, String)> =
                    base.iter().enumerate().map(|(j, c)| (c.clone(), self.increment_name(j))).collect();
                out.push(format!("{name} = {}", super::names::combination(&parts, &self.levels.style)));
            }
        }
        if self.id.ansatz.window.offset > 0 {
            out.push("x⁻: x at the previous step's start; the identity holds from the second step on".into());
        } else if self.levels.named.iter().any(|(_, n)| n.ends_with('⁻')) {
            out.push(format!("{0}⁻: {0} at the previous step's start ({0}⁻ = {0} on the first step)", self.state(0)));
        }
        out
    }

    fn over_ranges(&self) -> Vec<String> {
        let ranges: Vec<String> = self
            .ir
            .params
            .iter()
            .zip(&self.region.0)
            .map(|(p, i)| match i {
                Some(i) => format!("{} in {}", p.name, interval(i)),
                None => format!("{} unbounded", p.name),
            })
            .collect();
        let mut out = Vec::new();
        let head =
            if ranges.is_empty() { "for every dt > 0:".to_string() } else { format!("over {}:", ranges.join(", ")) };
        out.push(head);
        let d = &self.id.dissipation;
        if d.cross.is_some() {
            out.push("  D ⪰ 0: never".into());
        } else if d.squares.is_empty() {
            out.push("  D ≡ 0".into());
        } else {
            for s in &d.squares {
                let (c, text) = self.square(s);
                out.push(format!("  D ⪰ 0 along {text}: {}", self.condition(&c)));
            }
        }
        for (q, what) in [(&self.id.acceleration, "acceleration"), (&self.id.step_before, "step")] {
            if let Some(q) = q {
                let hat = if self.id.weight.is_some() { "\u{302}" } else { "" };
                let what = match what {
                    "acceleration" => format!("½dt²‖{}{hat}‖²_M", self.acceleration().unwrap_or("a")),
                    _ => format!("½‖{0} - {0}⁻‖²_K", self.state(0)),
                };
                out.push(format!("  Ẽ ⪰ 0 in its term {what}: {}", self.condition(q)));
            }
        }
        out
    }

    /// "c ≥ 0: proved" / "fails at p = …" / "undecided", c shown without dt's positive powers.
    fn condition(&self, c: &RatFn) -> String {
        let shown = without_positive_parts(c);
        if let Some(k) = shown.as_constant() {
            return if k.signum() >= 0 { "always".into() } else { format!("never (its coefficient is {})", self.r(c)) };
        }
        let verdict = match sign_over(c, &self.region) {
            Ok(s) if s.nonnegative => "proved".to_string(),
            Ok(s) => match s.negative_at {
                Some(at) => format!("fails at {}", self.point(&at)),
                None => "undecided".to_string(),
            },
            Err(_) => "undecided (overflow)".to_string(),
        };
        format!("{} ≥ 0: {verdict}", self.r(&shown))
    }

    /// A witness: the params, then dt where it has one more coordinate.
    fn point(&self, at: &[super::super::rational::Rat]) -> String {
        let names = self.ir.params.iter().map(|p| p.name.as_str()).chain(["dt"]);
        names.zip(at).map(|(n, v)| format!("{n} = {}", rat(*v))).collect::<Vec<_>>().join(", ")
    }

    fn at_defaults(&self) -> Vec<String> {
        let defaults: Vec<f64> = self.ir.params.iter().map(|p| p.default).collect();
        let shown: Vec<String> = self.ir.params.iter().map(|p| format!("{} = {}", p.name, p.default)).collect();
        let mut out = vec![if shown.is_empty() {
            "E's law:".to_string()
        } else {
            format!("at the defaults ({}):", shown.join(", "))
        }];
        for law in EnergyLaw::ALL {
            let claimed = if self.ir.energy == Some(law) { "  [the scheme's claim]" } else { "" };
            let text = match self.id.proves(law, &defaults, &|s| self.described(s)) {
                Ok(Proof::Holds) => "proved".to_string(),
                Ok(Proof::Fails(why)) => format!("refuted: {why}"),
                Ok(Proof::Undecided(why)) => format!("undecided: {why}"),
                Err(_) => "undecided: the exact coefficients overflow".to_string(),
            };
            out.push(format!("  {}: {text}{claimed}", law.name()));
        }
        out
    }

    /// The identity in one line: the kept energy and the dissipation.
    pub fn summary(&self) -> String {
        format!("Ẽ' - Ẽ = W - D with Ẽ = {} and D = {}", self.kept(), self.dissipation())
    }

    /// A square as the identity prints it: coefficient·‖vector‖²_B.
    pub fn described(&self, s: &Square) -> String {
        let (c, text) = self.square(s);
        if c.as_constant() == Some(super::super::rational::Rat::ONE) { text } else { format!("{}·{text}", self.c(&c)) }
    }
}

/// `r` without the factors that cannot change whether it is ≥ 0: dt's powers (dt > 0), a
/// positive constant, a denominator's even powers. A numerator's even powers are kept: where
/// they vanish, r does.
fn without_positive_parts(r: &RatFn) -> RatFn {
    let Ok(f) = super::factor::factor(r) else { return r.clone() };
    let mut out = RatFn::constant(super::super::rational::Rat::int(f.constant.signum()));
    for (p, e) in &f.num {
        if p.terms().count() == 1 && p.vars() == [super::poly::DT] {
            continue;
        }
        out = out.mul(&RatFn::poly(p.clone()).powi(*e as i32).unwrap_or_else(|_| RatFn::one())).unwrap_or(out);
    }
    for (p, e) in f.den.iter().filter(|(p, e)| e % 2 == 1 && !(p.terms().count() == 1 && p.vars() == [super::poly::DT]))
    {
        out = out.div(&RatFn::poly(p.clone()).powi(*e as i32).unwrap_or_else(|_| RatFn::one())).unwrap_or(out);
    }
    out
}

/// The differences of consecutive levels.
fn increments(chain: &[Lin]) -> Vec<Lin> {
    chain
        .windows(2)
        .filter_map(|w| Some(Lin(w[1].0.iter().zip(&w[0].0).map(|(a, b)| a.sub(b).ok()).collect::<Option<_>>()?)))
        .collect()
}

fn proportional(nu: &[RatFn], base: &[RatFn]) -> Option<RatFn> {
    let k = base.iter().position(|c| !c.is_zero())?;
    let c = nu[k].div(&base[k]).ok()?;
    nu.iter()
        .zip(base)
        .all(|(x, y)| y.mul(&c).and_then(|p| x.sub(&p)).is_ok_and(|d| d.is_zero()))
        .then_some(c)
        .filter(|c| !c.is_zero())
}

fn nonzero(v: &[RatFn]) -> Vec<usize> {
    v.iter().enumerate().filter(|(_, c)| !c.is_zero()).map(|(j, _)| j).collect()
}

fn rat(v: super::super::rational::Rat) -> String {
    if v.denom() == 1 { v.numer().to_string() } else { format!("{}/{}", v.numer(), v.denom()) }
}

fn interval(i: &Interval) -> String {
    format!(
        "{}{}, {}{}",
        if i.lo_closed { "[" } else { "(" },
        rat(i.lo),
        rat(i.hi),
        if i.hi_closed { "]" } else { ")" }
    )
}
