//! Affine combinations of time levels with scalar coefficients from the coefficient DAG.

use std::collections::BTreeMap;

use signorini_descriptors::Level;

use crate::ir::graph::{Graph, NodeId, Sym};

/// A vector known when a stage starts, or one of its new quantities.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Quantity {
    /// A state at the start of the step.
    State(usize),
    /// New quantity `index` of stage `stage`.
    Stage { stage: usize, index: usize },
}

/// The runtime's name for the same level.
impl From<Quantity> for Level {
    fn from(q: Quantity) -> Level {
        match q {
            Quantity::State(i) => Level::State(i),
            Quantity::Stage { stage, index } => Level::Stage(stage, index),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Key {
    Unknown,
    /// Another new quantity of the stage (only during elimination).
    New(usize),
    Known(Quantity),
}

/// Σ coefficient · level. `unknown` is the coefficient of the stage's unknown.
#[derive(Clone, Debug, PartialEq)]
pub struct Affine {
    pub unknown: NodeId,
    /// Coefficients of the known quantities, sorted; zero coefficients are dropped.
    pub known: Vec<(Quantity, NodeId)>,
    new: Vec<(usize, NodeId)>,
}

impl Affine {
    fn from_map(g: &mut Graph, map: BTreeMap<Key, NodeId>) -> Affine {
        let zero = g.zero();
        let mut a = Affine { unknown: zero, known: Vec::new(), new: Vec::new() };
        for (k, c) in map {
            if g.is_zero(c) {
                continue;
            }
            match k {
                Key::Unknown => a.unknown = c,
                Key::New(i) => a.new.push((i, c)),
                Key::Known(q) => a.known.push((q, c)),
            }
        }
        a
    }

    fn to_map(&self, g: &Graph) -> BTreeMap<Key, NodeId> {
        let mut m = BTreeMap::new();
        if !g.is_zero(self.unknown) {
            m.insert(Key::Unknown, self.unknown);
        }
        m.extend(self.new.iter().map(|(i, c)| (Key::New(*i), *c)));
        m.extend(self.known.iter().map(|(q, c)| (Key::Known(*q), *c)));
        m
    }

    pub fn known(g: &mut Graph, q: Quantity) -> Affine {
        let one = g.one();
        Affine::from_map(g, BTreeMap::from([(Key::Known(q), one)]))
    }

    pub fn unknown(g: &mut Graph) -> Affine {
        let one = g.one();
        Affine::from_map(g, BTreeMap::from([(Key::Unknown, one)]))
    }

    pub fn new_quantity(g: &mut Graph, index: usize) -> Affine {
        let one = g.one();
        Affine::from_map(g, BTreeMap::from([(Key::New(index), one)]))
    }

    pub fn add(&self, g: &mut Graph, other: &Affine) -> Affine {
        let mut m = self.to_map(g);
        for (k, c) in other.to_map(g) {
            let sum = match m.get(&k) {
                Some(&x) => g.add(x, c),
                None => c,
            };
            m.insert(k, sum);
        }
        Affine::from_map(g, m)
    }

    pub fn scale(&self, g: &mut Graph, s: NodeId) -> Affine {
        let m: BTreeMap<Key, NodeId> = self.to_map(g).into_iter().map(|(k, c)| (k, g.mul(s, c))).collect();
        Affine::from_map(g, m)
    }

    pub fn sub(&self, g: &mut Graph, other: &Affine) -> Affine {
        let m = g.constant(-1.0);
        let neg = other.scale(g, m);
        self.add(g, &neg)
    }

    /// Replaces every coefficient by `f` of it; coefficients that become zero drop out.
    pub fn map_coefs(&mut self, g: &mut Graph, f: &mut impl FnMut(&mut Graph, NodeId) -> NodeId) {
        self.unknown = f(g, self.unknown);
        for (_, c) in &mut self.known {
            *c = f(g, *c);
        }
        self.known.retain(|(_, c)| !g.is_zero(*c));
        for (_, c) in &mut self.new {
            *c = f(g, *c);
        }
        self.new.retain(|(_, c)| !g.is_zero(*c));
    }

    /// Whether new quantity `index` appears (with a nonzero coefficient).
    pub fn has_new(&self, index: usize) -> bool {
        self.new.iter().any(|(i, _)| *i == index)
    }

    /// Coefficient of new quantity `index`.
    pub fn new_coef(&self, g: &mut Graph, index: usize) -> NodeId {
        self.new.iter().find(|(i, _)| *i == index).map_or_else(|| g.zero(), |(_, c)| *c)
    }

    /// Solves `self = 0` for new quantity `index`: −(self − c·q)/c.
    pub fn solve_for(&self, g: &mut Graph, index: usize) -> Affine {
        let c = self.new_coef(g, index);
        let mut m = self.to_map(g);
        m.remove(&Key::New(index));
        let minus_inv = {
            let m1 = g.constant(-1.0);
            g.div(m1, c)
        };
        let rest = Affine::from_map(g, m);
        rest.scale(g, minus_inv)
    }

    /// Replaces new quantity `index` by `value`.
    pub fn substitute(&self, g: &mut Graph, index: usize, value: &Affine) -> Affine {
        if !self.has_new(index) {
            return self.clone();
        }
        let c = self.new_coef(g, index);
        let mut m = self.to_map(g);
        m.remove(&Key::New(index));
        let rest = Affine::from_map(g, m);
        let scaled = value.scale(g, c);
        rest.add(g, &scaled)
    }
}

/// Numeric value of a coefficient node for given scheme parameters, dt and t.
pub fn eval(g: &Graph, id: NodeId, params: &[f64], dt: f64, t: f64) -> f64 {
    eval_all(g, &[id], params, dt, t)[0]
}

/// The values of scheme scalars (params, dt and t are the only leaves), by the IR's one
/// evaluator.
pub fn eval_all(g: &Graph, roots: &[NodeId], params: &[f64], dt: f64, t: f64) -> Vec<f64> {
    crate::ir::eval::evaluate(g, roots, |s| scheme_leaf(s, params, dt, t))
}

/// A scheme coefficient's leaf: a param, dt or t.
pub fn scheme_leaf(s: Sym, params: &[f64], dt: f64, t: f64) -> f64 {
    match s {
        Sym::Param(i) => params.get(i as usize).copied().unwrap_or(f64::NAN),
        Sym::Dt => dt,
        Sym::Time => t,
        _ => f64::NAN,
    }
}
