//! The expression DAG: scalar nodes, hash-consed (equal subexpressions are one node), built
//! through constructors that fold constants and drop zeros and ones.

use std::collections::HashMap;

pub type NodeId = u32;

/// A leaf the kernel reads: geometry, parameters, case data, and the values and gradients of
/// the form's arguments at the quadrature point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sym {
    Param(u16),
    /// Component `comp` of field argument `arg`.
    Field {
        arg: u8,
        comp: u8,
    },
    /// ∂_dir of component `comp` of field argument `arg`.
    FieldGrad {
        arg: u8,
        comp: u8,
        dir: u8,
    },
    Test {
        comp: u8,
    },
    TestGrad {
        comp: u8,
        dir: u8,
    },
    /// Outward unit normal of the body at a facet point.
    Normal(u8),
    /// Diameter of the cell carrying the facet.
    CellDiameter,
    Coord(u8),
    Time,
    /// The time step (scheme coefficients only).
    Dt,
    /// Component `comp` (row-major for tensors) of case datum `id`.
    Coef {
        id: u16,
        comp: u8,
    },
    /// The variation parameter of a `derivative(e, u, d)` being lowered (its nesting level):
    /// `e` is lowered at u + s·d, differentiated in s and read at s = 0, so no seed outlives
    /// the lowering of its call.
    Seed(u8),
    /// A value read on the other surface of a contact pair, at the point facing the quadrature
    /// point (`opposite(e)`).
    Opposite(Facing),
    /// ∂_along of [`Sym::FieldGrad`] (read on a pair's facing side only: the gradient's rate
    /// as the facing point slides).
    FieldHess {
        arg: u8,
        comp: u8,
        dir: u8,
        along: u8,
    },
    /// ∂_along of [`Sym::Normal`]`(comp)` along the surface (read on a pair's facing side only:
    /// the normal's rate as the facing point slides, zero across the surface).
    NormalRate {
        comp: u8,
        along: u8,
    },
}

/// The leaves `opposite(e)` reads on the facing surface: those of the quadrature point's own
/// side, there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Facing {
    Field {
        arg: u8,
        comp: u8,
    },
    FieldGrad {
        arg: u8,
        comp: u8,
        dir: u8,
    },
    Test {
        comp: u8,
    },
    TestGrad {
        comp: u8,
        dir: u8,
    },
    /// The facing body's outward unit normal.
    Normal(u8),
    /// The facing point.
    Coord(u8),
    /// The diameter of the cell carrying the facing facet.
    CellDiameter,
    /// The facing point's rates as it slides ([`Sym::FieldHess`], [`Sym::NormalRate`]).
    FieldHess {
        arg: u8,
        comp: u8,
        dir: u8,
        along: u8,
    },
    NormalRate {
        comp: u8,
        along: u8,
    },
}

impl Facing {
    /// The leaf of the own side that reads, on the facing side, as this one.
    pub fn own(self) -> Sym {
        match self {
            Facing::Field { arg, comp } => Sym::Field { arg, comp },
            Facing::FieldGrad { arg, comp, dir } => Sym::FieldGrad { arg, comp, dir },
            Facing::Test { comp } => Sym::Test { comp },
            Facing::TestGrad { comp, dir } => Sym::TestGrad { comp, dir },
            Facing::Normal(k) => Sym::Normal(k),
            Facing::Coord(k) => Sym::Coord(k),
            Facing::CellDiameter => Sym::CellDiameter,
            Facing::FieldHess { arg, comp, dir, along } => Sym::FieldHess { arg, comp, dir, along },
            Facing::NormalRate { comp, along } => Sym::NormalRate { comp, along },
        }
    }
}

impl Sym {
    /// This leaf read on the facing surface, if it has a value there (a param, the time or a
    /// seed is the same on both sides; a coef is read at the facing point by the caller).
    pub fn facing(self) -> Option<Facing> {
        Some(match self {
            Sym::Field { arg, comp } => Facing::Field { arg, comp },
            Sym::FieldGrad { arg, comp, dir } => Facing::FieldGrad { arg, comp, dir },
            Sym::Test { comp } => Facing::Test { comp },
            Sym::TestGrad { comp, dir } => Facing::TestGrad { comp, dir },
            Sym::Normal(k) => Facing::Normal(k),
            Sym::Coord(k) => Facing::Coord(k),
            Sym::CellDiameter => Facing::CellDiameter,
            Sym::FieldHess { arg, comp, dir, along } => Facing::FieldHess { arg, comp, dir, along },
            Sym::NormalRate { comp, along } => Facing::NormalRate { comp, along },
            _ => return None,
        })
    }
}

/// A smooth function of one scalar: the language's `sin`, `cos`, `tan`, `exp` and `ln`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Exp,
    Ln,
}

impl Func {
    pub const ALL: [Func; 5] = [Func::Sin, Func::Cos, Func::Tan, Func::Exp, Func::Ln];

    /// Its name in the language, and the name of the `f64` method the generated code calls.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Exp => "exp",
            Func::Ln => "ln",
        }
    }

    pub fn named(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }

    /// Its value: the `f64` method of the same name, as the generated code computes it (so that
    /// folded constants, the evaluator and the kernels agree to the bit).
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Node {
    /// The bits of an f64 (so that nodes hash).
    Const(u64),
    Sym(Sym),
    Add(NodeId, NodeId),
    Mul(NodeId, NodeId),
    Neg(NodeId),
    Div(NodeId, NodeId),
    Powi(NodeId, i32),
    /// a^p for a constant real p (its bits), not an integer: NaN where a < 0.
    Powf(NodeId, u64),
    Sqrt(NodeId),
    /// H(a) = 1 if a > 0, else 0. Every non-smooth built-in is defined through it.
    Heaviside(NodeId),
    /// H(a) inside a built-in's definition (`proj_ball`'s regimes, the guard of `sqrt`'s
    /// derivative): the same function, but not a switch of the law's active set, which counts
    /// where the file's own `pos`, `neg`, `H`, ... turn (the contact points, not the regimes of a
    /// projection).
    Step(NodeId),
    /// sin, cos, tan, exp or ln of a node.
    Func(Func, NodeId),
    /// atan2(y, x): the angle of the point (x, y), in (−π, π].
    Atan2(NodeId, NodeId),
    /// A case datum evaluated at a point other than the quadrature point (`g(x + u)`): component
    /// `comp` of coef `id`, or its partial derivative with respect to the point's coordinates
    /// `dirs` (see [`Dirs`]), at the point [`Graph::point`]`(point)`, whose components are
    /// this node's children.
    CoefAt {
        id: u16,
        comp: u8,
        dirs: Dirs,
        point: u32,
    },
}

/// The coordinates a [`Node::CoefAt`] is differentiated along, sorted (partial derivatives
/// commute): at most [`Dirs::MAX`] of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct Dirs {
    len: u8,
    dirs: [u8; 3],
}

impl Dirs {
    /// The most derivatives a kernel takes of a coef at a point: a residual may read its
    /// gradient (`grad(g(x + u))`), its tangent one more, and a third leaves room for both.
    pub const MAX: usize = 3;

    pub fn as_slice(&self) -> &[u8] {
        &self.dirs[..self.len as usize]
    }

    /// One more derivative, along `k`; `None` past [`Dirs::MAX`].
    pub fn and(self, k: u8) -> Option<Dirs> {
        if self.len as usize == Self::MAX {
            return None;
        }
        let mut d = self;
        d.dirs[d.len as usize] = k;
        d.len += 1;
        d.dirs[..d.len as usize].sort_unstable();
        Some(d)
    }
}

#[derive(Default, Clone, Debug)]
pub struct Graph {
    nodes: Vec<Node>,
    index: HashMap<Node, NodeId>,
    /// The points coefs are evaluated at ([`Node::CoefAt`]), each once.
    points: Vec<Vec<NodeId>>,
    point_index: HashMap<Vec<NodeId>, u32>,
    /// Names from the source (`let mu`, `fn sn`), used for readable generated code.
    pub names: HashMap<NodeId, String>,
}

impl Graph {
    pub fn node(&self, id: NodeId) -> Node {
        self.nodes[id as usize]
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    fn intern(&mut self, n: Node) -> NodeId {
        if let Some(&id) = self.index.get(&n) {
            return id;
        }
        let id = self.nodes.len() as NodeId;
        self.nodes.push(n);
        self.index.insert(n, id);
        id
    }

    pub fn constant(&mut self, v: f64) -> NodeId {
        // -0.0 and 0.0 are one node.
        let v = if v == 0.0 { 0.0 } else { v };
        self.intern(Node::Const(v.to_bits()))
    }

    pub fn sym(&mut self, s: Sym) -> NodeId {
        self.intern(Node::Sym(s))
    }

    pub fn as_const(&self, id: NodeId) -> Option<f64> {
        match self.node(id) {
            Node::Const(b) => Some(f64::from_bits(b)),
            _ => None,
        }
    }

    pub fn is_zero(&self, id: NodeId) -> bool {
        self.as_const(id) == Some(0.0)
    }

    pub fn zero(&mut self) -> NodeId {
        self.constant(0.0)
    }

    pub fn one(&mut self) -> NodeId {
        self.constant(1.0)
    }

    pub fn add(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x + y),
            (Some(0.0), _) => return b,
            (_, Some(0.0)) => return a,
            _ => {}
        }
        if let Node::Neg(nb) = self.node(b)
            && nb == a
        {
            return self.zero();
        }
        if let Node::Neg(na) = self.node(a)
            && na == b
        {
            return self.zero();
        }
        if a == b {
            let two = self.constant(2.0);
            return self.mul(two, a);
        }
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        self.intern(Node::Add(a, b))
    }

    pub fn sub(&mut self, a: NodeId, b: NodeId) -> NodeId {
        let nb = self.neg(b);
        self.add(a, nb)
    }

    pub fn neg(&mut self, a: NodeId) -> NodeId {
        match self.node(a) {
            Node::Const(b) => self.constant(-f64::from_bits(b)),
            Node::Neg(x) => x,
            _ => self.intern(Node::Neg(a)),
        }
    }

    pub fn mul(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x * y),
            (Some(0.0), _) | (_, Some(0.0)) => return self.zero(),
            (Some(1.0), _) => return b,
            (_, Some(1.0)) => return a,
            (Some(-1.0), _) => return self.neg(b),
            (_, Some(-1.0)) => return self.neg(a),
            _ => {}
        }
        // Fold constant factors: c1·(c2·x) = (c1·c2)·x.
        if let Some(c1) = self.as_const(a)
            && let Node::Mul(x, y) = self.node(b)
            && let Some(c2) = self.as_const(x)
        {
            let c = self.constant(c1 * c2);
            return self.mul(c, y);
        }
        if self.as_const(b).is_some() && self.as_const(a).is_none() {
            return self.mul(b, a);
        }
        // Pull negations out so that -a*b and a*-b are one node.
        if let Node::Neg(x) = self.node(a) {
            let p = self.mul(x, b);
            return self.neg(p);
        }
        if let Node::Neg(y) = self.node(b) {
            let p = self.mul(a, y);
            return self.neg(p);
        }
        // Constants first, then by id: a canonical order for commutative products.
        let (a, b) = if self.as_const(b).is_some() || (self.as_const(a).is_none() && b < a) { (b, a) } else { (a, b) };
        self.intern(Node::Mul(a, b))
    }

    pub fn div(&mut self, a: NodeId, b: NodeId) -> NodeId {
        if let Some(c) = self.as_const(a)
            && c < 0.0
            && self.as_const(b).is_none()
        {
            let p = self.constant(-c);
            let q = self.div(p, b);
            return self.neg(q);
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.constant(x / y),
            (Some(0.0), _) => return self.zero(),
            (_, Some(1.0)) => return a,
            (_, Some(-1.0)) => return self.neg(a),
            _ => {}
        }
        if a == b {
            return self.one();
        }
        if let Node::Neg(x) = self.node(a) {
            let q = self.div(x, b);
            return self.neg(q);
        }
        if let Node::Neg(y) = self.node(b) {
            let q = self.div(a, y);
            return self.neg(q);
        }
        self.intern(Node::Div(a, b))
    }

    pub fn powi(&mut self, a: NodeId, k: i32) -> NodeId {
        match k {
            0 => return self.one(),
            1 => return a,
            -1 => {
                let one = self.one();
                return self.div(one, a);
            }
            _ => {}
        }
        if let Some(x) = self.as_const(a) {
            return self.constant(x.powi(k));
        }
        self.intern(Node::Powi(a, k))
    }

    /// a^p for a constant real p; an integer p is [`Graph::powi`], p = 1/2 [`Graph::sqrt`].
    pub fn powf(&mut self, a: NodeId, p: f64) -> NodeId {
        if p.fract() == 0.0 && p.abs() <= i32::MAX as f64 {
            return self.powi(a, p as i32);
        }
        if p == 0.5 {
            return self.sqrt(a);
        }
        match self.as_const(a) {
            Some(x) => self.constant(x.powf(p)),
            None => self.intern(Node::Powf(a, p.to_bits())),
        }
    }

    pub fn sqrt(&mut self, a: NodeId) -> NodeId {
        match self.as_const(a) {
            Some(x) => self.constant(x.sqrt()),
            None => self.intern(Node::Sqrt(a)),
        }
    }

    pub fn heaviside(&mut self, a: NodeId) -> NodeId {
        match self.as_const(a) {
            Some(x) => self.constant(if x > 0.0 { 1.0 } else { 0.0 }),
            None => self.intern(Node::Heaviside(a)),
        }
    }

    /// H(a) as a built-in's inner step (not a switch; see [`Node::Step`]).
    pub fn step(&mut self, a: NodeId) -> NodeId {
        match self.as_const(a) {
            Some(x) => self.constant(if x > 0.0 { 1.0 } else { 0.0 }),
            None => self.intern(Node::Step(a)),
        }
    }

    pub fn func(&mut self, f: Func, a: NodeId) -> NodeId {
        match self.as_const(a) {
            Some(x) => self.constant(f.apply(x)),
            None => self.intern(Node::Func(f, a)),
        }
    }

    /// The components of point `i` (see [`Node::CoefAt`]).
    pub fn point(&self, i: u32) -> &[NodeId] {
        &self.points[i as usize]
    }

    /// Component `comp` of coef `id` at the point with components `at`, differentiated along
    /// `dirs`.
    pub fn coef_at(&mut self, id: u16, comp: u8, dirs: Dirs, at: &[NodeId]) -> NodeId {
        let point = match self.point_index.get(at) {
            Some(&i) => i,
            None => {
                let i = self.points.len() as u32;
                self.points.push(at.to_vec());
                self.point_index.insert(at.to_vec(), i);
                i
            }
        };
        self.intern(Node::CoefAt { id, comp, dirs, point })
    }

    pub fn atan2(&mut self, y: NodeId, x: NodeId) -> NodeId {
        match (self.as_const(y), self.as_const(x)) {
            (Some(a), Some(b)) => self.constant(a.atan2(b)),
            _ => self.intern(Node::Atan2(y, x)),
        }
    }

    /// Records a source name for a node (the first name given wins).
    pub fn name(&mut self, id: NodeId, name: &str) {
        if matches!(
            self.node(id),
            Node::Const(_)
                | Node::Sym(Sym::Field { .. } | Sym::FieldGrad { .. } | Sym::Test { .. } | Sym::TestGrad { .. })
        ) {
            return;
        }
        self.names.entry(id).or_insert_with(|| name.to_string());
    }

    /// Children of a node.
    pub fn children(&self, id: NodeId) -> impl Iterator<Item = NodeId> + '_ {
        let (a, b, point) = match self.node(id) {
            Node::CoefAt { point, .. } => (None, None, self.point(point)),
            n => {
                let (a, b) = Self::operands(n);
                (a, b, &[][..])
            }
        };
        a.into_iter().chain(b).chain(point.iter().copied())
    }

    fn operands(n: Node) -> (Option<NodeId>, Option<NodeId>) {
        match n {
            Node::Const(_) | Node::Sym(_) | Node::CoefAt { .. } => (None, None),
            Node::Add(x, y) | Node::Mul(x, y) | Node::Div(x, y) | Node::Atan2(x, y) => (Some(x), Some(y)),
            Node::Neg(x)
            | Node::Powi(x, _)
            | Node::Powf(x, _)
            | Node::Sqrt(x)
            | Node::Heaviside(x)
            | Node::Step(x)
            | Node::Func(_, x) => (Some(x), None),
        }
    }

    /// The nodes reachable from `roots`, children before parents (ids are created children
    /// first, so sorting by id is a topological order).
    pub fn reachable(&self, roots: impl IntoIterator<Item = NodeId>) -> Vec<NodeId> {
        let mut seen = vec![false; self.nodes.len()];
        let mut stack: Vec<NodeId> = roots.into_iter().collect();
        let mut out = Vec::new();
        while let Some(id) = stack.pop() {
            if std::mem::replace(&mut seen[id as usize], true) {
                continue;
            }
            out.push(id);
            stack.extend(self.children(id));
        }
        out.sort_unstable();
        out
    }

    /// `root` with every leaf `s` for which `map(s)` is some other leaf replaced by it, rebuilt
    /// through the constructors (children first: ids are a topological order).
    pub fn substitute(&mut self, root: NodeId, map: &impl Fn(Sym) -> Option<Sym>) -> NodeId {
        self.replace(root, &|g: &mut Graph, s| map(s).map(|t| g.sym(t)))
    }

    /// `root` with every leaf `s` for which `map(s)` is a node replaced by that node, rebuilt
    /// through the constructors, which fold what becomes constant (a seed set to 0).
    pub fn replace(&mut self, root: NodeId, map: &impl Fn(&mut Graph, Sym) -> Option<NodeId>) -> NodeId {
        let mut new: HashMap<NodeId, NodeId> = HashMap::new();
        for id in self.reachable([root]) {
            let c = |x: NodeId| new[&x];
            let rebuilt = match self.node(id) {
                Node::Const(_) => id,
                Node::Sym(s) => map(self, s).unwrap_or(id),
                Node::Add(a, b) => self.add(c(a), c(b)),
                Node::Mul(a, b) => self.mul(c(a), c(b)),
                Node::Div(a, b) => self.div(c(a), c(b)),
                Node::Neg(a) => self.neg(c(a)),
                Node::Powi(a, k) => self.powi(c(a), k),
                Node::Powf(a, p) => self.powf(c(a), f64::from_bits(p)),
                Node::Sqrt(a) => self.sqrt(c(a)),
                Node::Heaviside(a) => self.heaviside(c(a)),
                Node::Step(a) => self.step(c(a)),
                Node::Func(f, a) => self.func(f, c(a)),
                Node::Atan2(y, x) => self.atan2(c(y), c(x)),
                Node::CoefAt { id: coef, comp, dirs, point } => {
                    let at: Vec<NodeId> = self.point(point).iter().map(|&p| c(p)).collect();
                    self.coef_at(coef, comp, dirs, &at)
                }
            };
            new.insert(id, rebuilt);
        }
        new[&root]
    }

    /// Whether `id` depends on any symbol accepted by `pred`.
    pub fn depends_on(&self, id: NodeId, pred: impl Fn(Sym) -> bool) -> bool {
        self.reachable([id]).into_iter().any(|n| matches!(self.node(n), Node::Sym(s) if pred(s)))
    }
}
