//! Time schemes: per stage, the affine relations between time levels are solved for the new
//! quantities other than the unknown, and the residual becomes a sum of forms applied to affine
//! combinations `α·unknown + Σ βₖ·knownₖ`, whose tangent is Σ coef·α·(form tangent).
//!
//! Scalars (parameters, lets, dt, t) live in one coefficient DAG; the generated stepper
//! evaluates it for a given dt. A pivot of the elimination is checked not to vanish anywhere in
//! the declared parameter ranges (by sampling them, with dt > 0).

mod affine;
pub mod layout;
pub mod print;
pub mod simplify;

use std::collections::HashMap;

pub use affine::{Affine, eval_all, scheme_leaf};

pub use crate::check::SchemeDef;
use crate::check::{Global, ParamRange, Unit, const_eval};
use crate::diagnostic::Diagnostic;
use crate::ir::graph::{Graph, NodeId, Sym};
use crate::source::Span;
use crate::syntax::ast::{self, BinOp, Expr, ExprKind, Ident};

/// A vector known when a stage starts, or one of its new quantities.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Quantity {
    /// A state at the start of the step.
    State(usize),
    /// New quantity `index` of stage `stage`.
    Stage { stage: usize, index: usize },
}

#[derive(Clone, Debug)]
pub struct SchemeParamInfo {
    pub name: String,
    pub default: f64,
    pub range: Option<ParamRange>,
    /// The declaration (`alpha = 0.05 in [0, 1/3]`).
    pub span: Span,
}

/// A slot the scheme applies: a form of a case's files, bound by name.
#[derive(Clone, Debug)]
pub struct SlotUse {
    pub name: String,
    /// Time levels it is applied to; 0 for a load (applied to a time).
    pub fields: usize,
    /// Its name in the `uses` line.
    pub span: Span,
}

/// One form application in a residual: `coef · form(args)` at time `time`.
#[derive(Clone, Debug)]
pub struct Term {
    pub coef: NodeId,
    pub form: String,
    /// Field arguments (empty for loads).
    pub args: Vec<Affine>,
    /// When the form is evaluated.
    pub time: NodeId,
}

#[derive(Clone, Debug)]
pub struct StageIr {
    pub name: String,
    pub time: NodeId,
    /// Names of the stage's new quantities; the unknown is first.
    pub quantities: Vec<String>,
    /// Each new quantity in terms of the unknown and the known quantities.
    pub values: Vec<Affine>,
    /// Residual = Σ terms (the right-hand side moved over with a minus sign).
    pub terms: Vec<Term>,
}

#[derive(Clone, Debug)]
pub struct InitialIr {
    /// The state solved for at the start.
    pub state: usize,
    pub terms: Vec<Term>,
}

#[derive(Clone, Debug)]
pub struct SchemeIr {
    pub name: String,
    /// The declaration (for its doc comment and location).
    pub span: Span,
    pub params: Vec<SchemeParamInfo>,
    /// The slots it applies, in `uses` order.
    pub slots: Vec<SlotUse>,
    pub states: Vec<String>,
    pub graph: Graph,
    pub initial: Option<InitialIr>,
    pub stages: Vec<StageIr>,
    /// For each state, the quantity holding its value at the end of the step.
    pub updates: Vec<Quantity>,
    /// The author's claims (`claim order = 2`): name and value, a function of the params.
    pub claims: Vec<(String, NodeId)>,
    /// `claim energy = conserving | dissipative`: the energy law the run's guard applies.
    pub energy: Option<EnergyLaw>,
}

/// How a scheme's augmented energy E_aug (kinetic + elastic + the contact law's energy) may
/// change from step to step with constant loads (docs/mathematics.md §5).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnergyLaw {
    /// Kept, except on steps where points enter or leave contact, where it may jump by at most
    /// the contact energy of those points (Crank–Nicolson gains on release, midpoint on entry).
    Conserving,
    /// Never grows.
    Dissipative,
}

impl EnergyLaw {
    pub const ALL: [EnergyLaw; 2] = [EnergyLaw::Conserving, EnergyLaw::Dissipative];

    /// Its name in `claim energy = NAME`.
    pub fn name(self) -> &'static str {
        match self {
            EnergyLaw::Conserving => "conserving",
            EnergyLaw::Dissipative => "dissipative",
        }
    }
}

/// A declaration a scheme `let` hides (W0002).
struct Hidden {
    span: Option<Span>,
    what: String,
    /// A name of the file, which the scheme does not see.
    of_the_file: bool,
}

/// The properties a scheme may claim, and what each means.
pub const CLAIMS: &[(&str, &str)] = &[
    ("order", "the order of accuracy in time"),
    ("rho_inf", "the spectral radius of the one-step map as ωΔt → ∞"),
    (
        "energy",
        "the energy law: `conserving` (E_aug kept except where contact starts or ends) or `dissipative` (E_aug never grows)",
    ),
    ("cfl", "the largest ω_max Δt at which the scheme is stable (an explicit scheme): a run beyond it is refused"),
];

impl SchemeIr {
    /// The claims' values at these param values (in `params` order).
    pub fn claims_at(&self, params: &[f64]) -> Vec<(String, f64)> {
        self.claims
            .iter()
            .map(|(name, node)| (name.clone(), affine::eval(&self.graph, *node, params, 1.0, 0.0)))
            .collect()
    }
}

/// Compiles every scheme; errors go to `diags`.
pub fn compile(prog: &Unit, defs: &[SchemeDef], diags: &mut Vec<Diagnostic>) -> Vec<SchemeIr> {
    let mut out = Vec::new();
    for d in defs {
        let mut warnings = Vec::new();
        let result = Compiler::new(prog, d, &mut warnings).run();
        diags.append(&mut warnings);
        match result {
            Ok(ir) => out.push(ir),
            Err(mut e) => diags.append(&mut e),
        }
    }
    out
}

/// What a name means inside a scheme.
#[derive(Clone, Debug)]
enum Value {
    Scalar(NodeId),
    Vector(Affine),
}

struct Compiler<'a> {
    prog: &'a Unit,
    def: &'a SchemeDef,
    g: Graph,
    params: Vec<SchemeParamInfo>,
    diags: Vec<Diagnostic>,
    warnings: &'a mut Vec<Diagnostic>,
    /// Names visible in the current stage: scalars and known or new vectors.
    scope: HashMap<String, Value>,
    /// Quantities of the stage being compiled: name → index.
    new: Vec<String>,
    stage_index: usize,
    /// Per `uses` entry: the first application (fields, span), once seen.
    applied: Vec<Option<(usize, Span)>>,
}

const SCHEME_BUILTINS: &[&str] = &["dt", "t", "pi"];
/// Scalar functions available in schemes (every other call is a slot application).
const SCHEME_FUNCTIONS: &[&str] = &["sqrt", "abs"];

impl<'a> Compiler<'a> {
    fn new(prog: &'a Unit, def: &'a SchemeDef, warnings: &'a mut Vec<Diagnostic>) -> Self {
        Compiler {
            prog,
            def,
            g: Graph::default(),
            params: Vec::new(),
            diags: Vec::new(),
            warnings,
            scope: HashMap::new(),
            new: Vec::new(),
            stage_index: 0,
            applied: vec![None; def.uses.len()],
        }
    }

    fn error(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    fn run(mut self) -> Result<SchemeIr, Vec<Diagnostic>> {
        let def = self.def;
        // Parameters.
        for (i, p) in def.params.iter().enumerate() {
            if let Some(prev) = def.params[..i].iter().find(|q| q.name.name == p.name.name) {
                self.error(
                    Diagnostic::error(
                        "E0103",
                        format!("duplicate parameter `{}`", p.name.name),
                        p.name.span,
                        "repeated here",
                    )
                    .with_label(prev.name.span, "first here"),
                );
            }
            let default = match const_eval(&p.default) {
                Ok(v) if v.is_finite() => v,
                _ => {
                    self.error(Diagnostic::error(
                        "E0603",
                        "a scheme parameter default must be a finite constant",
                        p.default.span,
                        "not a constant",
                    ));
                    f64::NAN
                }
            };
            let range = p.range.as_ref().and_then(|r| {
                let (lo, hi) = (const_eval(&r.lo).ok()?, const_eval(&r.hi).ok()?);
                Some(ParamRange { lo, lo_closed: r.lo_closed, hi, hi_closed: r.hi_closed })
            });
            if let Some(r) = range
                && default.is_finite()
                && !r.contains(default)
            {
                self.error(Diagnostic::error(
                    "E0601",
                    format!("default of `{}` is outside its range", p.name.name),
                    p.default.span,
                    format!("{default} is not in {}", r.describe()),
                ));
            }
            self.params.push(SchemeParamInfo { name: p.name.name.clone(), default, range, span: p.span });
            let node = self.g.sym(Sym::Param(i as u16));
            self.g.name(node, &p.name.name);
            self.scope.insert(p.name.name.clone(), Value::Scalar(node));
        }
        self.check_uses();
        let dt = self.g.sym(Sym::Dt);
        let t = self.g.sym(Sym::Time);
        self.scope.insert("dt".into(), Value::Scalar(dt));
        self.scope.insert("t".into(), Value::Scalar(t));
        let pi = self.g.constant(std::f64::consts::PI);
        self.scope.insert("pi".into(), Value::Scalar(pi));
        if def.states.is_empty() {
            self.error(
                Diagnostic::error(
                    "E0805",
                    format!("scheme `{}` declares no state", def.name.name),
                    def.name.span,
                    "no `state` line",
                )
                .with_help("declare the states: `state u, v, a`"),
            );
            return Err(self.diags);
        }
        for (i, s) in def.states.iter().enumerate() {
            if self.scope.contains_key(&s.name) {
                self.error(Diagnostic::error(
                    "E0102",
                    format!("`{}` is defined twice", s.name),
                    s.span,
                    "already a name of this scheme",
                ));
            }
            self.scope.insert(s.name.clone(), Value::Vector(Affine::known(&mut self.g, Quantity::State(i))));
        }
        for (name, value) in &def.lets {
            self.bind_let(name, value);
        }
        if !self.diags.is_empty() {
            return Err(self.diags);
        }
        let initial = def.initial.as_ref().and_then(|i| self.initial(i));
        let mut stages = Vec::new();
        for (s, stage) in def.stages.iter().enumerate() {
            self.stage_index = s;
            if let Some(ir) = self.stage(stage, s == def.stages.len() - 1) {
                stages.push(ir);
            }
        }
        if stages.is_empty() && self.diags.is_empty() {
            self.error(Diagnostic::error(
                "E0805",
                format!("scheme `{}` has no stage", def.name.name),
                def.name.span,
                "no unknown, relations or residual",
            ));
        }
        // Each state's value at the end of the step: its primed quantity in the last stage.
        let mut updates = Vec::new();
        if let Some(last) = stages.last() {
            for s in &def.states {
                let primed = format!("{}'", s.name);
                match last.quantities.iter().position(|q| *q == primed) {
                    Some(index) => updates.push(Quantity::Stage { stage: stages.len() - 1, index }),
                    None => {
                        let last =
                            def.stages.last().and_then(|s| s.name.as_ref().map(|n| n.span)).unwrap_or(def.name.span);
                        self.error(
                            Diagnostic::error(
                                "E0806",
                                format!("state `{}` gets no new value", s.name),
                                s.span,
                                format!("declared here, but there is no `{primed}` in the last stage"),
                            )
                            .with_label(last, "the last stage")
                            .with_help(format!("relate `{primed}` to the other quantities, or make it the unknown")),
                        );
                    }
                }
            }
        }
        self.initial_values(def);
        let mut slots = Vec::new();
        let complete = self.diags.is_empty();
        for (u, applied) in def.uses.iter().zip(self.applied.clone()) {
            match applied {
                Some((fields, _)) => slots.push(SlotUse { name: u.name.clone(), fields, span: u.span }),
                // Reported only when every residual compiled (an error may hide an application).
                None if !complete => {}
                None => self.error(
                    Diagnostic::error("E0817", format!("slot `{}` is never applied", u.name), u.span, "unused slot")
                        .with_help("apply it in a residual, or remove it from the `uses` line"),
                ),
            }
        }
        let (claims, energy) = self.claims();
        if !self.diags.is_empty() {
            return Err(self.diags);
        }
        let ir = SchemeIr {
            name: def.name.name.clone(),
            span: def.span,
            params: self.params,
            slots,
            states: def.states.iter().map(|s| s.name.clone()).collect(),
            graph: self.g,
            initial,
            stages,
            updates,
            claims,
            energy,
        };
        Ok(ir)
    }

    /// `claim NAME = EXPR`: a known property, a scalar of the params (not of t or dt); and
    /// `claim energy = LAW`.
    fn claims(&mut self) -> (Vec<(String, NodeId)>, Option<EnergyLaw>) {
        let mut out: Vec<(String, NodeId)> = Vec::new();
        let mut energy = None;
        for (i, (name, e)) in self.def.claims.iter().enumerate() {
            if !CLAIMS.iter().any(|(c, _)| *c == name.name) {
                let known: Vec<&str> = CLAIMS.iter().map(|(c, _)| *c).collect();
                let mut d = Diagnostic::error(
                    "E0819",
                    format!("`{}` is not a property a scheme can claim", name.name),
                    name.span,
                    "unknown claim",
                )
                .with_note(format!("claims: {}", known.join(", ")));
                if let Some(s) = crate::check::suggest_name(&name.name, known.into_iter()) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
                self.error(d);
                continue;
            }
            if let Some((prev, _)) = self.def.claims[..i].iter().find(|(p, _)| p.name == name.name) {
                self.error(
                    Diagnostic::error("E0102", format!("`{}` is claimed twice", name.name), name.span, "again here")
                        .with_label(prev.span, "first here"),
                );
                continue;
            }
            if name.name == "energy" {
                let law = match &e.kind {
                    ExprKind::Name(id) => EnergyLaw::ALL.into_iter().find(|l| l.name() == id.name),
                    _ => None,
                };
                match law {
                    Some(law) => energy = Some(law),
                    None => {
                        let names: Vec<&str> = EnergyLaw::ALL.iter().map(|l| l.name()).collect();
                        let mut d = Diagnostic::error(
                            "E0819",
                            "an energy law is `conserving` or `dissipative`",
                            e.span,
                            "not an energy law",
                        )
                        .with_note(format!("energy laws: {}", names.join(", ")));
                        if let ExprKind::Name(id) = &e.kind
                            && let Some(s) = crate::check::suggest_name(&id.name, names.into_iter())
                        {
                            d = d.with_help(format!("did you mean `{s}`?"));
                        }
                        self.error(d);
                    }
                }
                continue;
            }
            match self.value(e) {
                Some(Value::Scalar(n)) if !self.g.depends_on(n, |s| matches!(s, Sym::Time | Sym::Dt)) => {
                    out.push((name.name.clone(), n))
                }
                Some(_) => self.error(Diagnostic::error(
                    "E0819",
                    "a claim is a number or a function of the scheme's parameters",
                    e.span,
                    "not a function of the parameters alone",
                )),
                None => {}
            }
        }
        (out, energy)
    }

    fn is_slot(&self, name: &str) -> bool {
        self.def.uses.iter().any(|u| u.name == name)
    }

    /// Duplicate and reserved names in the `uses` line.
    fn check_uses(&mut self) {
        for (i, u) in self.def.uses.iter().enumerate() {
            if let Some(prev) = self.def.uses[..i].iter().find(|p| p.name == u.name) {
                self.error(
                    Diagnostic::error("E0103", format!("duplicate slot `{}`", u.name), u.span, "repeated here")
                        .with_label(prev.span, "first here"),
                );
            } else if SCHEME_FUNCTIONS.contains(&u.name.as_str()) || SCHEME_BUILTINS.contains(&u.name.as_str()) {
                self.error(Diagnostic::error(
                    "E0106",
                    format!("`{}` is a built-in name", u.name),
                    u.span,
                    "cannot be a slot",
                ));
            }
        }
    }

    /// Records that a slot is applied to `fields` levels (0: a load); every application of a
    /// slot must agree.
    fn record_application(&mut self, f: &Ident, fields: usize, span: Span) -> bool {
        let i = self.def.uses.iter().position(|u| u.name == f.name).expect("a slot");
        match self.applied[i] {
            None => {
                self.applied[i] = Some((fields, span));
                true
            }
            Some((n, _)) if n == fields => true,
            Some((n, first)) => {
                let what = |k: usize| if k == 0 { "a time (a load)".to_string() } else { format!("{k} time level(s)") };
                self.error(
                    Diagnostic::error(
                        "E0201",
                        format!("slot `{}` is applied to {} here but to {} before", f.name, what(fields), what(n)),
                        span,
                        format!("{} argument(s)", fields),
                    )
                    .with_label(first, "first application"),
                );
                false
            }
        }
    }

    /// A call that is neither a slot nor a scalar function.
    fn unknown_slot(&mut self, f: &Ident) {
        let uses = &self.def.uses;
        let mut d = Diagnostic::error(
            "E0816",
            format!("`{}` is not a slot of scheme `{}`", f.name, self.def.name.name),
            f.span,
            "not in the `uses` line",
        );
        if let Some(s) = crate::check::suggest_name(&f.name, uses.iter().map(|u| u.name.as_str())) {
            d = d.with_help(format!("did you mean `{s}`?"));
        } else if uses.is_empty() {
            d = d.with_help(format!(
                "a scheme names the forms it applies: add `uses {}` inside scheme `{}`",
                self.called_names().join(", "),
                self.def.name.name
            ));
        } else {
            let names: Vec<&str> = uses.iter().map(|u| u.name.as_str()).collect();
            d = d.with_help(format!("add it to the `uses` line: `uses {}, {}`", names.join(", "), f.name));
        }
        if let Some(Global::Form(_)) = self.prog.globals.get(&f.name) {
            d = d.with_note("schemes apply slots, not the forms of imported files: a case binds each slot to a form");
        }
        self.error(d);
    }

    /// A state read at the start of a step needs a value at the start of the run: the
    /// displacement (the first state) and `v` are the problem's, any other an `initial` line's
    /// (E0820: without one it would start at zero, silently). Another state never read is W0005.
    fn initial_values(&mut self, def: &crate::check::SchemeDef) {
        fn names(e: &Expr, out: &mut Vec<String>) {
            match &e.kind {
                ExprKind::Name(n) => out.push(n.name.clone()),
                ExprKind::Call(_, args) | ExprKind::Vector(args) => args.iter().for_each(|a| names(a, out)),
                ExprKind::Neg(a) => names(a, out),
                ExprKind::Binary(_, a, b) | ExprKind::Index(a, b) => {
                    names(a, out);
                    names(b, out);
                }
                ExprKind::Number(_) => {}
            }
        }
        let mut read = Vec::new();
        def.lets.iter().for_each(|(_, e)| names(e, &mut read));
        for stage in &def.stages {
            stage.at.iter().for_each(|e| names(e, &mut read));
            stage.lets.iter().for_each(|(_, e)| names(e, &mut read));
            stage.relates.iter().for_each(|r| names(&r.value, &mut read));
            if let Some(r) = &stage.residual {
                names(&r.lhs, &mut read);
                names(&r.rhs, &mut read);
            }
        }
        let solved = def.initial.as_ref().map(|i| i.unknown.name.as_str());
        for (i, s) in def.states.iter().enumerate() {
            // The displacement and `v` are also the run's output (its observables read them).
            let output = i == 0 || s.name == "v";
            let given = output || solved == Some(s.name.as_str());
            if !read.contains(&s.name) && !output {
                self.warnings.push(
                    Diagnostic::warning("W0005", format!("state `{}` is never read", s.name), s.span, "declared here")
                        .with_note(
                            "its value at the start of a step does not enter the step: it is only carried along",
                        ),
                );
            } else if !given {
                self.error(
                    Diagnostic::error(
                        "E0820",
                        format!("state `{}` is read before anything sets it", s.name),
                        s.span,
                        "read at the start of every step, and of the first",
                    )
                    .with_note("the problem gives the displacement (the first state) and `v`; any other state starts from an `initial` line")
                    .with_help(format!("solve for it at t = 0: `initial {}: ... == ...`", s.name)),
                );
            }
        }
    }

    /// Every name applied in the scheme's residuals, in order of appearance.
    fn called_names(&self) -> Vec<String> {
        fn walk(e: &Expr, out: &mut Vec<String>) {
            match &e.kind {
                ExprKind::Call(f, args) => {
                    if !SCHEME_FUNCTIONS.contains(&f.name.as_str()) && !out.contains(&f.name) {
                        out.push(f.name.clone());
                    }
                    args.iter().for_each(|a| walk(a, out));
                }
                ExprKind::Neg(a) => walk(a, out),
                ExprKind::Binary(_, a, b) => {
                    walk(a, out);
                    walk(b, out);
                }
                _ => {}
            }
        }
        let mut out = Vec::new();
        let residuals = self
            .def
            .initial
            .iter()
            .map(|i| &i.residual)
            .chain(self.def.stages.iter().filter_map(|s| s.residual.as_ref()));
        for r in residuals {
            walk(&r.lhs, &mut out);
            walk(&r.rhs, &mut out);
        }
        out
    }

    /// The declaration a `let` named `name` (declared at `at`) would hide, if any.
    fn shadowed(&self, name: &str, at: Span) -> Option<Hidden> {
        let mine = |span: Option<Span>, what: &str| Some(Hidden { span, what: what.into(), of_the_file: false });
        if let Some(p) = self.def.params.iter().find(|p| p.name.name == name) {
            return mine(Some(p.name.span), "the scheme's parameter");
        }
        if let Some(s) = self.def.states.iter().find(|s| s.name == name) {
            return mine(Some(s.span), "the state");
        }
        if let Some((n, _)) = self.def.lets.iter().find(|(n, _)| n.name == name && n.span.start < at.start) {
            return mine(Some(n.span), "the scheme's `let`");
        }
        if SCHEME_BUILTINS.contains(&name) {
            return mine(None, "the built-in");
        }
        // Schemes do not see the file's names, but a reader of the file may think so.
        let g = self.prog.globals.get(name)?;
        let span = g.span(&self.prog.params, &self.prog.coefs, &self.prog.forms);
        Some(Hidden {
            span: (span.end > span.start).then_some(span),
            what: format!("the file's {}", g.kind()),
            of_the_file: true,
        })
    }

    fn bind_let(&mut self, name: &Ident, value: &Expr) {
        if let Some(hidden) = self.shadowed(&name.name, name.span) {
            let mut w = Diagnostic::warning(
                "W0002",
                format!("`{}` hides {} `{}`", name.name, hidden.what, name.name),
                name.span,
                "this `let` hides it",
            )
            .with_help(format!("rename the `let` if `{}` should keep its meaning", name.name));
            if let Some(at) = hidden.span {
                w = w.with_label(at, "declared here");
            }
            if hidden.of_the_file {
                w = w.with_note(format!(
                    "a scheme sees only its own names: inside it `{}` is this `let`, though a reader may take it for the file's",
                    name.name
                ));
            }
            self.warnings.push(w);
        }
        if let Some(v) = self.value(value) {
            match v {
                Value::Scalar(n) => {
                    self.g.name(n, &name.name);
                    self.scope.insert(name.name.clone(), Value::Scalar(n));
                }
                Value::Vector(_) => self.error(
                    Diagnostic::error(
                        "E0807",
                        "a scheme `let` must be a scalar",
                        value.span,
                        "this is a combination of time levels",
                    )
                    .with_help("introduce a new quantity with `relate NAME = ...` instead"),
                ),
            }
        }
    }

    fn initial(&mut self, init: &ast::Initial) -> Option<InitialIr> {
        let Some(state) = self.def.states.iter().position(|s| s.name == init.unknown.name) else {
            self.error(Diagnostic::error(
                "E0808",
                format!("`{}` is not a state", init.unknown.name),
                init.unknown.span,
                "the initial problem solves for a state",
            ));
            return None;
        };
        let saved = self.scope.clone();
        // Within the initial problem the state is the unknown.
        self.new = vec![init.unknown.name.clone()];
        let unknown = Affine::unknown(&mut self.g);
        self.scope.insert(init.unknown.name.clone(), Value::Vector(unknown));
        let time = self.g.sym(Sym::Time);
        let terms = self.residual(&init.residual, time, &[]);
        self.scope = saved;
        let terms = terms?;
        if !terms.iter().any(|t| t.args.iter().any(|a| !self.g.is_zero(a.unknown))) {
            self.error(Diagnostic::error(
                "E0809",
                "the initial residual does not depend on its unknown",
                init.residual.span,
                format!("no form is applied to `{}`", init.unknown.name),
            ));
            return None;
        }
        Some(InitialIr { state, terms })
    }

    fn stage(&mut self, st: &ast::Stage, last: bool) -> Option<StageIr> {
        let name = st.name.as_ref().map_or_else(|| format!("stage{}", self.stage_index + 1), |n| n.name.clone());
        let at_span = st.span.unwrap_or(self.def.name.span);
        let Some(unknown) = &st.unknown else {
            self.error(
                Diagnostic::error("E0805", format!("stage `{name}` has no unknown"), at_span, "no `unknown` line")
                    .with_help(format!(
                        "`unknown {}'` names the quantity Newton solves for",
                        self.def.states.first().map_or("u", |s| s.name.as_str())
                    )),
            );
            return None;
        };
        let Some(residual) = &st.residual else {
            self.error(Diagnostic::error(
                "E0805",
                format!("stage `{name}` has no residual"),
                at_span,
                "no `residual ... == ...` line",
            ));
            return None;
        };
        let saved = self.scope.clone();
        for (n, v) in &st.lets {
            self.bind_let(n, v);
        }
        let time = match &st.at {
            Some(e) => match self.value(e) {
                Some(Value::Scalar(n)) => n,
                Some(Value::Vector(_)) => {
                    self.error(Diagnostic::error(
                        "E0301",
                        "a stage time must be a scalar",
                        e.span,
                        "a combination of time levels",
                    ));
                    return None;
                }
                None => return None,
            },
            None => {
                let (t, dt) = (self.g.sym(Sym::Time), self.g.sym(Sym::Dt));
                self.g.add(t, dt)
            }
        };
        if let (Some(e), Some(at)) = (&st.at, self.not_finite_at(time)) {
            self.error(
                Diagnostic::error("E0818", format!("the time of stage `{name}` is not finite"), e.span, at)
                    .with_help("a stage time is t plus a finite multiple of dt for every parameter value in range"),
            );
            return None;
        }
        // New quantities: the unknown, the relations' left-hand sides, and the names their
        // right-hand sides introduce.
        self.new = vec![unknown.name.clone()];
        let mut lhs_spans = Vec::new();
        for r in &st.relates {
            if r.name.name == unknown.name {
                // A relation for the unknown determines one of the other new quantities.
                continue;
            }
            if self.new.contains(&r.name.name) {
                self.error(
                    Diagnostic::error(
                        "E0810",
                        format!("`{}` is related twice", r.name.name),
                        r.name.span,
                        "second relation",
                    )
                    .with_help("one relation per new quantity"),
                );
            } else if self.scope.contains_key(&r.name.name) {
                self.error(Diagnostic::error(
                    "E0810",
                    format!("`{}` is already known", r.name.name),
                    r.name.span,
                    "cannot be related here",
                ));
            } else {
                self.new.push(r.name.name.clone());
                lhs_spans.push(r.name.span);
            }
        }
        for n in &st.news {
            if st.relates.iter().any(|r| r.name.name == n.name && r.name.name != unknown.name) {
                // Declared and related: new either way.
                continue;
            }
            if self.new.contains(&n.name) || self.scope.contains_key(&n.name) {
                self.error(Diagnostic::error(
                    "E0810",
                    format!("`{}` is already a quantity of this stage or a name of the scheme", n.name),
                    n.span,
                    "declared again here",
                ));
            } else {
                self.new.push(n.name.clone());
            }
        }
        for r in &st.relates {
            self.collect_new_names(&r.value, last);
        }
        let n_new = self.new.len();
        for (i, q) in self.new.clone().iter().enumerate() {
            let v = if i == 0 { Affine::unknown(&mut self.g) } else { Affine::new_quantity(&mut self.g, i) };
            self.scope.insert(q.clone(), Value::Vector(v));
        }
        // Equations: lhs − rhs = 0, affine in the new quantities.
        let mut equations: Vec<(Affine, Span, Option<usize>)> = Vec::new();
        for (k, r) in st.relates.iter().enumerate() {
            let Some(Value::Vector(lhs)) = self.scope.get(&r.name.name).cloned() else {
                continue;
            };
            match self.value(&r.value) {
                Some(Value::Vector(rhs)) => {
                    let eq = lhs.sub(&mut self.g, &rhs);
                    let own = self.new.iter().position(|q| *q == r.name.name);
                    equations.push((eq, r.span, own));
                    let _ = k;
                }
                Some(Value::Scalar(_)) => self.error(
                    Diagnostic::error(
                        "E0301",
                        "a relation must give a combination of time levels",
                        r.value.span,
                        "this is a scalar",
                    )
                    .with_label(r.name.span, "a vector quantity"),
                ),
                None => {}
            }
        }
        if !self.diags.is_empty() {
            self.scope = saved;
            return None;
        }
        if equations.len() + 1 != n_new {
            let missing: Vec<String> =
                self.new[1..].iter().filter(|q| !st.relates.iter().any(|r| r.name.name == **q)).cloned().collect();
            self.error(
                Diagnostic::error(
                    "E0811",
                    format!(
                        "stage `{name}` has {} new quantities besides its unknown but {} relations",
                        n_new - 1,
                        equations.len()
                    ),
                    st.name.as_ref().map_or(unknown.span, |n| n.span),
                    "the relations do not determine the new quantities",
                )
                .with_note(format!("quantities without a relation: {}", missing.join(", "))),
            );
            self.scope = saved;
            return None;
        }
        // Gaussian elimination of the new quantities other than the unknown.
        let mut solved: Vec<Option<Affine>> = vec![None; n_new];
        solved[0] = Some(Affine::unknown(&mut self.g));
        let mut pending: Vec<(Affine, Span, Option<usize>)> = equations;
        while let Some((eq, span, own)) = pending.first().cloned() {
            pending.remove(0);
            let candidates: Vec<usize> = (1..n_new).filter(|&q| solved[q].is_none() && eq.has_new(q)).collect();
            let pivot = own.filter(|o| candidates.contains(o)).or_else(|| candidates.first().copied());
            let Some(q) = pivot else {
                let open: Vec<String> =
                    (1..n_new).filter(|&q| solved[q].is_none()).map(|q| format!("`{}`", self.new[q])).collect();
                self.error(
                    Diagnostic::error(
                        "E0812",
                        "this relation determines no new quantity",
                        span,
                        "it involves no quantity the relations before it leave open",
                    )
                    .with_note(format!("still undetermined: {}", open.join(", ")))
                    .with_help("each relation must involve a new quantity not yet given by the others"),
                );
                self.scope = saved;
                return None;
            };
            let c = eq.new_coef(&mut self.g, q);
            if let Err(why) = self.check_pivot(c) {
                self.error(
                    Diagnostic::error(
                        "E0802",
                        format!("solving this relation for `{}` divides by a coefficient that can vanish", self.new[q]),
                        span,
                        why,
                    )
                    .with_help("restrict the parameter range, or relate the quantities differently"),
                );
                self.scope = saved;
                return None;
            }
            // q = −(eq − c·q)/c
            let value = eq.solve_for(&mut self.g, q);
            for other in pending.iter_mut() {
                other.0 = other.0.substitute(&mut self.g, q, &value);
            }
            for s in solved.iter_mut().flatten() {
                *s = s.substitute(&mut self.g, q, &value);
            }
            solved[q] = Some(value);
        }
        let values: Vec<Affine> = solved.into_iter().map(|v| v.expect("every quantity solved")).collect();
        for (i, q) in self.new.clone().iter().enumerate() {
            self.scope.insert(q.clone(), Value::Vector(values[i].clone()));
        }
        let terms = self.residual(residual, time, &values);
        let quantities = self.new.clone();
        self.scope = saved;
        let terms = terms?;
        if !terms.iter().any(|t| t.args.iter().any(|a| !self.g.is_zero(a.unknown))) {
            self.error(Diagnostic::error(
                "E0809",
                "the residual does not depend on the unknown",
                residual.span,
                format!("no form is applied to a level containing `{}`", unknown.name),
            ));
            return None;
        }
        // Later stages see this stage's quantities as known values.
        for (i, q) in quantities.iter().enumerate() {
            let v = Affine::known(&mut self.g, Quantity::Stage { stage: self.stage_index, index: i });
            self.scope.insert(q.clone(), Value::Vector(v));
        }
        Some(StageIr { name, time, quantities, values, terms })
    }

    /// The new level `s'` of a state `s` on a right-hand side is a new quantity (`a'` in
    /// Newmark's relations). Every other name must be declared (a state, a param, a `let`, the
    /// unknown, a relation's left-hand side or a `new` quantity): an unknown one is an error
    /// with the closest names, reported when the relation is evaluated.
    fn collect_new_names(&mut self, e: &Expr, last: bool) {
        match &e.kind {
            ExprKind::Name(id) => {
                if !self.scope.contains_key(&id.name)
                    && !self.new.contains(&id.name)
                    && self.is_new_level(&id.name)
                    && self.is_vector_name(&id.name, last)
                {
                    self.new.push(id.name.clone());
                }
            }
            ExprKind::Call(_, args) => args.iter().for_each(|a| self.collect_new_names(a, last)),
            ExprKind::Neg(a) => self.collect_new_names(a, last),
            ExprKind::Binary(_, a, b) | ExprKind::Index(a, b) => {
                self.collect_new_names(a, last);
                self.collect_new_names(b, last);
            }
            ExprKind::Vector(items) => items.iter().for_each(|a| self.collect_new_names(a, last)),
            ExprKind::Number(_) => {}
        }
    }

    /// Whether `name` is `s'` for a state `s`.
    fn is_new_level(&self, name: &str) -> bool {
        name.strip_suffix('\'').is_some_and(|s| self.def.states.iter().any(|st| st.name == s))
    }

    /// The names a scheme's expression may use here, for "did you mean".
    fn visible_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self.scope.keys().cloned().collect();
        names.extend(self.new.iter().cloned());
        names.extend(self.def.states.iter().map(|s| format!("{}'", s.name)));
        names.extend(self.def.uses.iter().map(|u| u.name.clone()));
        names.sort();
        names.dedup();
        names
    }

    /// Whether an unknown name may be a new quantity: not a global or built-in name.
    fn is_vector_name(&self, name: &str, _last: bool) -> bool {
        !self.prog.globals.contains_key(name)
            && !SCHEME_BUILTINS.contains(&name)
            && !crate::check::BUILTIN_VALUES.contains(&name)
    }

    /// Checks that a pivot coefficient keeps one sign, away from zero, over the parameter
    /// ranges and dt > 0.
    /// Where (params, dt) a coefficient is not finite, among the pivot check's samples.
    fn not_finite_at(&self, c: NodeId) -> Option<String> {
        let samples: Vec<Vec<f64>> = self.params.iter().map(|p| p.samples()).collect();
        let mut points: Vec<Vec<f64>> = vec![Vec::new()];
        for s in &samples {
            points = points.iter().flat_map(|p| s.iter().map(move |v| [p.as_slice(), &[*v]].concat())).collect();
        }
        for values in &points {
            for dt in [1e-4, 1e-2, 1.0, 100.0] {
                let v = affine::eval(&self.g, c, values, dt, 0.0);
                if !v.is_finite() {
                    let ps: Vec<String> =
                        self.params.iter().zip(values).map(|(p, v)| format!("{} = {v}, ", p.name)).collect();
                    return Some(format!("{v} at {}dt = {dt}, t = 0", ps.concat()));
                }
            }
        }
        None
    }

    fn check_pivot(&self, c: NodeId) -> Result<(), String> {
        let samples: Vec<Vec<f64>> = self.params.iter().map(|p| p.samples()).collect();
        let mut index = vec![0usize; samples.len()];
        let mut sign = 0.0;
        loop {
            let values: Vec<f64> = index.iter().zip(&samples).map(|(&i, s)| s[i]).collect();
            for dt in [1e-4, 1e-2, 1.0, 100.0] {
                let v = affine::eval(&self.g, c, &values, dt, 0.0);
                let described = || {
                    let ps: Vec<String> =
                        self.params.iter().zip(&values).map(|(p, v)| format!("{} = {v}", p.name)).collect();
                    let shown = if v == 0.0 { "0".to_string() } else { format!("{v:e}") };
                    format!(
                        "it is {shown} at {}dt = {dt}",
                        if ps.is_empty() { String::new() } else { format!("{}, ", ps.join(", ")) }
                    )
                };
                if !v.is_finite() || v == 0.0 {
                    return Err(described());
                }
                if sign == 0.0 {
                    sign = v.signum();
                } else if v.signum() != sign {
                    return Err(format!("it changes sign: {}", described()));
                }
            }
            // Next combination of samples.
            let mut k = 0;
            loop {
                if k == index.len() {
                    return Ok(());
                }
                index[k] += 1;
                if index[k] < samples[k].len() {
                    break;
                }
                index[k] = 0;
                k += 1;
            }
        }
    }

    /// A residual `lhs == rhs` as a list of terms (rhs with flipped signs).
    fn residual(&mut self, r: &ast::Residual, time: NodeId, _values: &[Affine]) -> Option<Vec<Term>> {
        let mut lhs = self.form_sum(&r.lhs, time)?;
        let rhs = self.form_sum(&r.rhs, time)?;
        let minus = self.g.constant(-1.0);
        for mut t in rhs {
            t.coef = self.g.mul(minus, t.coef);
            lhs.push(t);
        }
        Some(lhs)
    }

    /// A sum of scalar multiples of form applications.
    fn form_sum(&mut self, e: &Expr, time: NodeId) -> Option<Vec<Term>> {
        match &e.kind {
            ExprKind::Call(f, _) if !self.is_slot(&f.name) && !SCHEME_FUNCTIONS.contains(&f.name.as_str()) => {
                self.unknown_slot(f);
                None
            }
            ExprKind::Call(f, args) if self.is_slot(&f.name) => {
                let one = self.g.one();
                // A slot applied to nothing or to one scalar is a load (a function of time).
                let first = match args.first() {
                    Some(a) => Some(self.value(a)?),
                    None => None,
                };
                let is_load = args.len() <= 1 && !matches!(first, Some(Value::Vector(_)));
                if !self.record_application(f, if is_load { 0 } else { args.len() }, e.span) {
                    return None;
                }
                if is_load {
                    // A load: its argument is the time.
                    let at = match args.as_slice() {
                        [] => time,
                        [a] => match self.value(a)? {
                            Value::Scalar(n) => n,
                            Value::Vector(_) => {
                                self.error(Diagnostic::error(
                                    "E0301",
                                    format!("`{}` takes the time, not a time level", f.name),
                                    a.span,
                                    "a combination of time levels",
                                ));
                                return None;
                            }
                        },
                        _ => {
                            self.error(Diagnostic::error(
                                "E0201",
                                format!("`{}` takes at most one argument (the time)", f.name),
                                e.span,
                                format!("{} arguments", args.len()),
                            ));
                            return None;
                        }
                    };
                    return Some(vec![Term { coef: one, form: f.name.clone(), args: Vec::new(), time: at }]);
                }
                let mut affine_args = Vec::new();
                for a in args {
                    match self.value(a)? {
                        Value::Vector(v) => affine_args.push(v),
                        Value::Scalar(_) => {
                            self.error(Diagnostic::error(
                                "E0301",
                                format!("`{}` is applied to time levels", f.name),
                                a.span,
                                "this is a scalar",
                            ));
                            return None;
                        }
                    }
                }
                Some(vec![Term { coef: one, form: f.name.clone(), args: affine_args, time }])
            }
            ExprKind::Binary(op @ (BinOp::Add | BinOp::Sub), a, b) => {
                let mut x = self.form_sum(a, time)?;
                let y = self.form_sum(b, time)?;
                let sign = self.g.constant(if *op == BinOp::Add { 1.0 } else { -1.0 });
                for mut t in y {
                    t.coef = self.g.mul(sign, t.coef);
                    x.push(t);
                }
                Some(x)
            }
            ExprKind::Neg(a) => {
                let mut x = self.form_sum(a, time)?;
                let m = self.g.constant(-1.0);
                x.iter_mut().for_each(|t| t.coef = self.g.mul(m, t.coef));
                Some(x)
            }
            ExprKind::Binary(BinOp::Mul, a, b) => {
                let (scalar, sum) = if self.is_form_sum(a) { (b, a) } else { (a, b) };
                let s = self.scalar(scalar)?;
                let mut x = self.form_sum(sum, time)?;
                x.iter_mut().for_each(|t| t.coef = self.g.mul(s, t.coef));
                Some(x)
            }
            ExprKind::Binary(BinOp::Div, a, b) => {
                let s = self.scalar(b)?;
                let mut x = self.form_sum(a, time)?;
                x.iter_mut().for_each(|t| t.coef = self.g.div(t.coef, s));
                Some(x)
            }
            _ => {
                self.error(
                    Diagnostic::error(
                        "E0813",
                        "a residual side is a sum of forms applied to time levels",
                        e.span,
                        "not a form application",
                    )
                    .with_help(self.residual_help(e)),
                );
                None
            }
        }
    }

    /// What a residual side should look like, in this scheme's own names: its slots applied to
    /// its states' new levels (and the closest slot to a misspelt name).
    fn residual_help(&self, e: &Expr) -> String {
        let slots: Vec<&str> = self.def.uses.iter().map(|u| u.name.as_str()).collect();
        if let ExprKind::Name(id) = &e.kind
            && let Some(close) = crate::check::suggest_name(&id.name, slots.iter().copied())
        {
            return format!("did you mean the slot `{close}`, applied to a time level: `{close}(...)`?");
        }
        let state = self.def.states.first().map_or("u", |s| s.name.as_str());
        match slots.first() {
            Some(first) => format!(
                "apply the slots of the `uses` line ({}) to time levels, e.g. `{first}({state}')`",
                slots.join(", ")
            ),
            None => "name the forms the scheme applies in a `uses` line, and apply them to time levels".into(),
        }
    }

    fn is_form_sum(&self, e: &Expr) -> bool {
        match &e.kind {
            ExprKind::Call(f, _) => self.is_slot(&f.name) || !SCHEME_FUNCTIONS.contains(&f.name.as_str()),
            ExprKind::Neg(a) => self.is_form_sum(a),
            ExprKind::Binary(BinOp::Add | BinOp::Sub, a, b) => self.is_form_sum(a) || self.is_form_sum(b),
            ExprKind::Binary(BinOp::Mul, a, b) => self.is_form_sum(a) || self.is_form_sum(b),
            ExprKind::Binary(BinOp::Div, a, _) => self.is_form_sum(a),
            _ => false,
        }
    }

    fn scalar(&mut self, e: &Expr) -> Option<NodeId> {
        match self.value(e)? {
            Value::Scalar(n) => Some(n),
            Value::Vector(_) => {
                self.error(Diagnostic::error("E0301", "expected a scalar", e.span, "a combination of time levels"));
                None
            }
        }
    }

    /// A scalar, or an affine combination of time levels; a division by zero or a non-finite
    /// constant is refused where it is written.
    fn value(&mut self, e: &Expr) -> Option<Value> {
        let v = self.value_inner(e)?;
        if let Value::Scalar(n) = v
            && let Some(x) = self.g.as_const(n).filter(|x| !x.is_finite())
        {
            self.error(not_finite(e.span, &format!("evaluates to {x}")));
            return None;
        }
        Some(v)
    }

    fn value_inner(&mut self, e: &Expr) -> Option<Value> {
        match &e.kind {
            ExprKind::Vector(_) | ExprKind::Index(..) => {
                self.error(crate::check::problem_only(e.span));
                None
            }
            ExprKind::Number(v) => Some(Value::Scalar(self.g.constant(*v))),
            ExprKind::Name(id) => match self.scope.get(&id.name) {
                Some(v) => Some(v.clone()),
                None => {
                    let what = match self.prog.globals.get(&id.name) {
                        Some(Global::Form(_)) => "a form: apply it to time levels in a residual",
                        Some(Global::Param(_)) => "a form parameter: schemes see their own parameters only",
                        Some(_) => "not usable in a scheme",
                        None => "not defined in this scheme",
                    };
                    let mut d =
                        Diagnostic::error("E0101", format!("unknown name `{}` in scheme", id.name), id.span, what);
                    let base = id.name.trim_end_matches('\'');
                    let state = self.def.states.iter().any(|s| s.name == base);
                    if id.name.ends_with("''") && state {
                        d = d.with_help(format!(
                            "a state has two levels in a step: `{base}` at its start and `{base}'` at its end"
                        ));
                    } else if let Some(close) =
                        crate::check::suggest_name(&id.name, self.visible_names().iter().map(String::as_str))
                    {
                        d = d.with_help(format!("did you mean `{close}`?"));
                    } else if id.name.ends_with('\'') {
                        d = d.with_help(
                            "primed quantities exist in the last stage: relate them, or make one the unknown",
                        );
                    } else {
                        d = d.with_help(format!(
                            "declare it: a parameter in `scheme {}(...)`, a `let`, or `new {}` for a quantity \
                             that only the relations determine",
                            self.def.name.name, id.name
                        ));
                    }
                    self.error(d);
                    None
                }
            },
            ExprKind::Neg(a) => Some(match self.value(a)? {
                Value::Scalar(n) => Value::Scalar(self.g.neg(n)),
                Value::Vector(v) => {
                    let m = self.g.constant(-1.0);
                    Value::Vector(v.scale(&mut self.g, m))
                }
            }),
            ExprKind::Binary(op, a, b) => {
                let (x, y) = (self.value(a)?, self.value(b)?);
                if let (BinOp::Div, Value::Scalar(q)) = (op, &y)
                    && self.g.is_zero(*q)
                {
                    self.error(not_finite(e.span, "divides by zero"));
                    return None;
                }
                match (op, x, y) {
                    (BinOp::Add, Value::Scalar(p), Value::Scalar(q)) => Some(Value::Scalar(self.g.add(p, q))),
                    (BinOp::Sub, Value::Scalar(p), Value::Scalar(q)) => Some(Value::Scalar(self.g.sub(p, q))),
                    (BinOp::Mul, Value::Scalar(p), Value::Scalar(q)) => Some(Value::Scalar(self.g.mul(p, q))),
                    (BinOp::Div, Value::Scalar(p), Value::Scalar(q)) => Some(Value::Scalar(self.g.div(p, q))),
                    (BinOp::Pow, Value::Scalar(p), Value::Scalar(_)) => match crate::check::const_value(b) {
                        Some(k) if k.fract() == 0.0 && k.abs() <= 64.0 => Some(Value::Scalar(self.g.powi(p, k as i32))),
                        _ => {
                            self.error(Diagnostic::error(
                                "E0303",
                                "exponent must be a constant integer",
                                b.span,
                                "not a constant integer",
                            ));
                            None
                        }
                    },
                    (BinOp::Add, Value::Vector(p), Value::Vector(q)) => Some(Value::Vector(p.add(&mut self.g, &q))),
                    (BinOp::Sub, Value::Vector(p), Value::Vector(q)) => Some(Value::Vector(p.sub(&mut self.g, &q))),
                    (BinOp::Mul, Value::Scalar(s), Value::Vector(v))
                    | (BinOp::Mul, Value::Vector(v), Value::Scalar(s)) => Some(Value::Vector(v.scale(&mut self.g, s))),
                    (BinOp::Div, Value::Vector(v), Value::Scalar(s)) => {
                        let one = self.g.one();
                        let inv = self.g.div(one, s);
                        Some(Value::Vector(v.scale(&mut self.g, inv)))
                    }
                    (op, _, _) => {
                        let why = match op {
                            BinOp::Add | BinOp::Sub => "adds a scalar to a time level",
                            BinOp::Mul => "multiplies two time levels",
                            BinOp::Div => "divides by a time level",
                            BinOp::Pow => "raises a time level to a power",
                        };
                        self.error(
                            Diagnostic::error(
                                "E0814",
                                "not an affine relation between time levels",
                                e.span,
                                format!("this {why}"),
                            )
                            .with_note(
                                "relations and form arguments are combinations Σ cₖ·levelₖ with scalar coefficients",
                            ),
                        );
                        None
                    }
                }
            }
            ExprKind::Call(f, args) => {
                if self.is_slot(&f.name) {
                    self.error(Diagnostic::error(
                        "E0813",
                        format!("slot `{}` applied outside a residual", f.name),
                        e.span,
                        "forms belong in `residual` lines",
                    ));
                    return None;
                }
                let vals: Vec<NodeId> = args.iter().map(|a| self.scalar(a)).collect::<Option<_>>()?;
                let node = match (f.name.as_str(), vals.as_slice()) {
                    ("sqrt", [x]) => self.g.sqrt(*x),
                    ("abs", [x]) => {
                        let h = self.g.heaviside(*x);
                        let m = self.g.neg(*x);
                        let hm = self.g.heaviside(m);
                        let s = self.g.sub(h, hm);
                        self.g.mul(*x, s)
                    }
                    _ => {
                        self.error(Diagnostic::error(
                            "E0101",
                            format!("`{}` is not available in schemes", f.name),
                            f.span,
                            "schemes use arithmetic, sqrt and abs",
                        ));
                        return None;
                    }
                };
                Some(Value::Scalar(node))
            }
        }
    }
}

impl SchemeParamInfo {
    /// Values at which a pivot is checked: the default, and the ends of the range (just inside
    /// open ends; a large value for infinite ones).
    fn samples(&self) -> Vec<f64> {
        let mut s = vec![self.default];
        if let Some(r) = self.range {
            let span = if r.lo.is_finite() && r.hi.is_finite() { r.hi - r.lo } else { 1.0 };
            let lo = if r.lo.is_finite() { if r.lo_closed { r.lo } else { r.lo + 1e-6 * span } } else { -1e6 };
            let hi = if r.hi.is_finite() { if r.hi_closed { r.hi } else { r.hi - 1e-6 * span } } else { 1e6 };
            s.extend([lo, hi, 0.5 * (lo + hi)]);
        }
        s
    }
}

fn not_finite(span: Span, label: &str) -> Diagnostic {
    Diagnostic::error("E0004", "constant arithmetic is not finite", span, label)
        .with_note("a division by zero or an overflow of double precision, after simplification")
}
