//! The rules of a scheme's names and slots: its parameters (distinct, constant defaults in
//! their ranges), its `uses` line, its states, what its `let`s hide, its claims, which states
//! need an initial value, and how its slots are applied. The scheme compiler applies them as
//! it reads a scheme, so that a scheme whose declarations are wrong stops before its stages;
//! nothing here builds coefficients.

use signorini_descriptors::ParamRange;

use super::{Global, Unit, const_eval, suggest_name};
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::{self, Expr, ExprKind, Ident};

/// A scheme as written.
#[derive(Clone, Debug)]
pub struct SchemeDef {
    pub name: Ident,
    pub params: Vec<ast::SchemeParam>,
    pub uses: Vec<Ident>,
    pub states: Vec<Ident>,
    pub lets: Vec<(Ident, Expr)>,
    pub initial: Option<ast::Initial>,
    pub claims: Vec<(Ident, Expr)>,
    pub estimates: Vec<Expr>,
    pub stages: Vec<ast::Stage>,
    pub span: Span,
}

/// A scheme parameter, checked: its default and range as values.
#[derive(Clone, Debug)]
pub struct SchemeParamInfo {
    pub name: String,
    pub default: f64,
    pub range: Option<ParamRange>,
    /// The declaration (`alpha = 0.05 in [0, 1/3]`).
    pub span: Span,
    /// The range as written.
    pub range_expr: Option<ast::Range>,
}

/// Names every scheme sees: the step, the time, π.
pub const SCHEME_BUILTINS: &[&str] = &["dt", "t", "pi"];
/// Scalar functions available in schemes (every other call is a slot application).
pub const SCHEME_FUNCTIONS: &[&str] = &["sqrt", "abs"];

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

/// Whether `name` is a slot of the scheme (named in its `uses` line).
pub fn is_slot(def: &SchemeDef, name: &str) -> bool {
    def.uses.iter().any(|u| u.name == name)
}

/// Whether `name` is `s'` for a state `s`.
pub fn is_new_level(def: &SchemeDef, name: &str) -> bool {
    name.strip_suffix('\'').is_some_and(|s| def.states.iter().any(|st| st.name == s))
}

/// Whether an unknown name may be a new quantity: not a global or built-in name.
pub fn may_be_quantity(unit: &Unit, name: &str) -> bool {
    !unit.globals.contains_key(name) && !SCHEME_BUILTINS.contains(&name) && !super::BUILTIN_VALUES.contains(&name)
}

/// The parameters: distinct names (E0103), finite constant defaults (E0603) inside their
/// ranges (E0601). A default that is no constant is NaN.
pub fn params(unit: &Unit, def: &SchemeDef, errors: &mut Vec<Diagnostic>) -> Vec<SchemeParamInfo> {
    let mut out = Vec::new();
    for (i, p) in def.params.iter().enumerate() {
        if let Some(prev) = def.params[..i].iter().find(|q| q.name.name == p.name.name) {
            errors.push(
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
                errors.push(Diagnostic::error(
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
            errors.push(Diagnostic::error(
                "E0601",
                format!("default of `{}` is outside its range", p.name.name),
                p.default.span,
                format!(
                    "{default} is not in {}",
                    super::range_written(&unit.sources, p.range.as_ref().expect("a range"))
                ),
            ));
        }
        out.push(SchemeParamInfo {
            name: p.name.name.clone(),
            default,
            range,
            span: p.span,
            range_expr: p.range.clone(),
        });
    }
    out
}

/// Duplicate (E0103) and reserved (E0106) names in the `uses` line.
pub fn uses(def: &SchemeDef, errors: &mut Vec<Diagnostic>) {
    for (i, u) in def.uses.iter().enumerate() {
        if let Some(prev) = def.uses[..i].iter().find(|p| p.name == u.name) {
            errors.push(
                Diagnostic::error("E0103", format!("duplicate slot `{}`", u.name), u.span, "repeated here")
                    .with_label(prev.span, "first here"),
            );
        } else if SCHEME_FUNCTIONS.contains(&u.name.as_str()) || SCHEME_BUILTINS.contains(&u.name.as_str()) {
            errors.push(Diagnostic::error(
                "E0106",
                format!("`{}` is a built-in name", u.name),
                u.span,
                "cannot be a slot",
            ));
        }
    }
}

/// The `state` line: at least one state (E0805; `false` without), each a new name (E0102).
pub fn states(def: &SchemeDef, errors: &mut Vec<Diagnostic>) -> bool {
    if def.states.is_empty() {
        errors.push(
            Diagnostic::error(
                "E0805",
                format!("scheme `{}` declares no state", def.name.name),
                def.name.span,
                "no `state` line",
            )
            .with_help("declare the states: `state u, v, a`"),
        );
        return false;
    }
    let mut seen: Vec<&str> = def.params.iter().map(|p| p.name.name.as_str()).collect();
    seen.extend(SCHEME_BUILTINS);
    for s in &def.states {
        if seen.contains(&s.name.as_str()) {
            errors.push(Diagnostic::error(
                "E0102",
                format!("`{}` is defined twice", s.name),
                s.span,
                "already a name of this scheme",
            ));
        }
        seen.push(&s.name);
    }
    true
}

/// A declaration a scheme `let` hides.
struct Hidden {
    span: Option<Span>,
    what: String,
    /// A name of the file, which the scheme does not see.
    of_the_file: bool,
}

/// The declaration a `let` named `name` (declared at `at`) would hide, if any.
fn shadowed(unit: &Unit, def: &SchemeDef, name: &str, at: Span) -> Option<Hidden> {
    let mine = |span: Option<Span>, what: &str| Some(Hidden { span, what: what.into(), of_the_file: false });
    if let Some(p) = def.params.iter().find(|p| p.name.name == name) {
        return mine(Some(p.name.span), "the scheme's parameter");
    }
    if let Some(s) = def.states.iter().find(|s| s.name == name) {
        return mine(Some(s.span), "the state");
    }
    if let Some((n, _)) = def.lets.iter().find(|(n, _)| n.name == name && n.span.start < at.start) {
        return mine(Some(n.span), "the scheme's `let`");
    }
    if SCHEME_BUILTINS.contains(&name) {
        return mine(None, "the built-in");
    }
    // Schemes do not see the file's names, but a reader of the file may think so.
    let g = unit.globals.get(name)?;
    let span = g.span(&unit.params, &unit.coefs, &unit.forms);
    Some(Hidden {
        span: (span.end > span.start).then_some(span),
        what: format!("the file's {}", g.kind()),
        of_the_file: true,
    })
}

/// W0002: a `let` of the scheme (or of a stage) that hides a parameter, a state, an earlier
/// `let`, a built-in or a name of the file.
pub fn let_hides(unit: &Unit, def: &SchemeDef, name: &Ident) -> Option<Diagnostic> {
    let hidden = shadowed(unit, def, &name.name, name.span)?;
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
    Some(w)
}

/// E0101: a name a scheme's expression uses that none of its declarations defines; `visible`
/// are the names it could have meant.
pub fn unknown_name(unit: &Unit, def: &SchemeDef, id: &Ident, visible: &[String]) -> Diagnostic {
    let what = match unit.globals.get(&id.name) {
        Some(Global::Form(_)) => "a form: apply it to time levels in a residual",
        Some(Global::Param(_)) => "a form parameter: schemes see their own parameters only",
        Some(_) => "not usable in a scheme",
        None => "not defined in this scheme",
    };
    let d = Diagnostic::error("E0101", format!("unknown name `{}` in scheme", id.name), id.span, what);
    let base = id.name.trim_end_matches('\'');
    let state = def.states.iter().any(|s| s.name == base);
    if id.name.ends_with("''") && state {
        d.with_help(format!("a state has two levels in a step: `{base}` at its start and `{base}'` at its end"))
    } else if let Some(close) = suggest_name(&id.name, visible.iter().map(String::as_str)) {
        d.with_help(format!("did you mean `{close}`?"))
    } else if id.name.ends_with('\'') {
        d.with_help("primed quantities exist in the last stage: relate them, or make one the unknown")
    } else {
        d.with_help(format!(
            "declare it: a parameter in `scheme {}(...)`, a `let`, or `new {}` for a quantity that only the \
             relations determine",
            def.name.name, id.name
        ))
    }
}

/// E0808: the state an `initial` line solves for, by index.
pub fn initial_state(def: &SchemeDef, init: &ast::Initial) -> Result<usize, Box<Diagnostic>> {
    def.states.iter().position(|s| s.name == init.unknown.name).ok_or_else(|| {
        Box::new(Diagnostic::error(
            "E0808",
            format!("`{}` is not a state", init.unknown.name),
            init.unknown.span,
            "the initial problem solves for a state",
        ))
    })
}

/// A state read at the start of a step needs a value at the start of the run: the
/// displacement (the first state) and `v` are the problem's, any other an `initial` line's
/// (E0820: without one it would start at zero, silently). Another state never read is W0005.
pub fn initial_values(def: &SchemeDef, warnings: &mut Vec<Diagnostic>, errors: &mut Vec<Diagnostic>) {
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
            warnings.push(
                Diagnostic::warning("W0005", format!("state `{}` is never read", s.name), s.span, "declared here")
                    .with_note("its value at the start of a step does not enter the step: it is only carried along"),
            );
        } else if !given {
            errors.push(
                Diagnostic::error(
                    "E0820",
                    format!("state `{}` is read before anything sets it", s.name),
                    s.span,
                    "read at the start of every step, and of the first",
                )
                .with_note(
                    "the problem gives the displacement (the first state) and `v`; any other state starts from an `initial` line",
                )
                .with_help(format!("solve for it at t = 0: `initial {}: ... == ...`", s.name)),
            );
        }
    }
}

/// What a claim says, once its name is known.
pub enum Claim<'a> {
    /// `claim energy = LAW`.
    Energy(EnergyLaw),
    /// `claim NAME = EXPR`: a number or a function of the parameters.
    Value(&'a Expr),
}

/// Claim `i` of the scheme: a known property (E0819), claimed once (E0102), and for `energy`
/// one of the laws (E0819).
pub fn claim(def: &SchemeDef, i: usize) -> Result<Claim<'_>, Box<Diagnostic>> {
    let (name, e) = &def.claims[i];
    if !CLAIMS.iter().any(|(c, _)| *c == name.name) {
        let known: Vec<&str> = CLAIMS.iter().map(|(c, _)| *c).collect();
        let mut d = Diagnostic::error(
            "E0819",
            format!("`{}` is not a property a scheme can claim", name.name),
            name.span,
            "unknown claim",
        )
        .with_note(format!("claims: {}", known.join(", ")));
        if let Some(s) = suggest_name(&name.name, known.into_iter()) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        return Err(Box::new(d));
    }
    if let Some((prev, _)) = def.claims[..i].iter().find(|(p, _)| p.name == name.name) {
        return Err(Box::new(
            Diagnostic::error("E0102", format!("`{}` is claimed twice", name.name), name.span, "again here")
                .with_label(prev.span, "first here"),
        ));
    }
    if name.name != "energy" {
        return Ok(Claim::Value(e));
    }
    let law = match &e.kind {
        ExprKind::Name(id) => EnergyLaw::ALL.into_iter().find(|l| l.name() == id.name),
        _ => None,
    };
    law.map(Claim::Energy).ok_or_else(|| {
        let names: Vec<&str> = EnergyLaw::ALL.iter().map(|l| l.name()).collect();
        let d =
            Diagnostic::error("E0819", "an energy law is `conserving` or `dissipative`", e.span, "not an energy law")
                .with_note(format!("energy laws: {}", names.join(", ")));
        Box::new(match &e.kind {
            ExprKind::Name(id) => match suggest_name(&id.name, names.into_iter()) {
                Some(s) => d.with_help(format!("did you mean `{s}`?")),
                None => d,
            },
            _ => d,
        })
    })
}

/// How the slots of a scheme are applied: every application of a slot to as many time levels
/// as the first (E0201), and every slot applied (E0817).
pub struct Applications {
    /// Per `uses` entry: the first application (levels, 0 for a load; span), once seen.
    first: Vec<Option<(usize, Span)>>,
}

impl Applications {
    pub fn new(def: &SchemeDef) -> Applications {
        Applications { first: vec![None; def.uses.len()] }
    }

    /// Records that slot `f` is applied to `fields` levels (0: a load) at `span`.
    pub fn record(&mut self, def: &SchemeDef, f: &Ident, fields: usize, span: Span) -> Result<(), Box<Diagnostic>> {
        let i = def.uses.iter().position(|u| u.name == f.name).expect("a slot");
        match self.first[i] {
            None => {
                self.first[i] = Some((fields, span));
                Ok(())
            }
            Some((n, _)) if n == fields => Ok(()),
            Some((n, first)) => {
                let what = |k: usize| if k == 0 { "a time (a load)".to_string() } else { format!("{k} time level(s)") };
                Err(Box::new(
                    Diagnostic::error(
                        "E0201",
                        format!("slot `{}` is applied to {} here but to {} before", f.name, what(fields), what(n)),
                        span,
                        format!("{} argument(s)", fields),
                    )
                    .with_label(first, "first application"),
                ))
            }
        }
    }

    /// The applied slots in `uses` order, with their levels. A slot never applied is E0817,
    /// reported only when `complete` (every residual compiled: an error may hide an
    /// application).
    pub fn applied<'d>(
        &self,
        def: &'d SchemeDef,
        complete: bool,
        errors: &mut Vec<Diagnostic>,
    ) -> Vec<(&'d Ident, usize)> {
        let mut out = Vec::new();
        for (u, first) in def.uses.iter().zip(&self.first) {
            match first {
                Some((fields, _)) => out.push((u, *fields)),
                None if !complete => {}
                None => errors.push(
                    Diagnostic::error("E0817", format!("slot `{}` is never applied", u.name), u.span, "unused slot")
                        .with_help("apply it in a residual, or remove it from the `uses` line"),
                ),
            }
        }
        out
    }
}

/// E0816: a call in a residual that is neither a slot nor a scalar function.
pub fn unknown_slot(unit: &Unit, def: &SchemeDef, f: &Ident) -> Diagnostic {
    let uses = &def.uses;
    let mut d = Diagnostic::error(
        "E0816",
        format!("`{}` is not a slot of scheme `{}`", f.name, def.name.name),
        f.span,
        "not in the `uses` line",
    );
    if let Some(s) = suggest_name(&f.name, uses.iter().map(|u| u.name.as_str())) {
        d = d.with_help(format!("did you mean `{s}`?"));
    } else if uses.is_empty() {
        d = d.with_help(format!(
            "a scheme names the forms it applies: add `uses {}` inside scheme `{}`",
            called_names(def).join(", "),
            def.name.name
        ));
    } else {
        let names: Vec<&str> = uses.iter().map(|u| u.name.as_str()).collect();
        d = d.with_help(format!("add it to the `uses` line: `uses {}, {}`", names.join(", "), f.name));
    }
    if let Some(Global::Form(_)) = unit.globals.get(&f.name) {
        d = d.with_note("schemes apply slots, not the forms of imported files: a case binds each slot to a form");
    }
    d
}

/// Every name applied in the scheme's residuals, in order of appearance.
fn called_names(def: &SchemeDef) -> Vec<String> {
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
    let residuals =
        def.initial.iter().map(|i| &i.residual).chain(def.stages.iter().filter_map(|s| s.residual.as_ref()));
    for r in residuals {
        walk(&r.lhs, &mut out);
        walk(&r.rhs, &mut out);
    }
    out
}

/// What a residual side should look like, in this scheme's own names: its slots applied to
/// its states' new levels (and the closest slot to a misspelt name).
pub fn residual_help(def: &SchemeDef, e: &Expr) -> String {
    let slots: Vec<&str> = def.uses.iter().map(|u| u.name.as_str()).collect();
    if let ExprKind::Name(id) = &e.kind
        && let Some(close) = suggest_name(&id.name, slots.iter().copied())
    {
        return format!("did you mean the slot `{close}`, applied to a time level: `{close}(...)`?");
    }
    let state = def.states.first().map_or("u", |s| s.name.as_str());
    match slots.first() {
        Some(first) => {
            format!(
                "apply the slots of the `uses` line ({}) to time levels, e.g. `{first}({state}')`",
                slots.join(", ")
            )
        }
        None => "name the forms the scheme applies in a `uses` line, and apply them to time levels".into(),
    }
}
