//! One diagnostic type for every check: a code, a message, a primary span with a caret,
//! secondary labels, notes and a help line. Rendered with file:line:col by codespan-reporting.

use codespan_reporting::diagnostic as cs;
use codespan_reporting::term;

use crate::source::{SourceMap, Span};

/// Every diagnostic code the compiler can emit, with its meaning in one line, in code order.
/// `Diagnostic::error`/`warning` check (in debug builds) that their code is listed here; the
/// ui corpus (compiler/tests/ui) exercises each one, and docs/language.md lists them all.
pub const CODES: &[(&str, &str)] = &[
    ("E0001", "syntax error"),
    (
        "E0002",
        "nesting or size limit exceeded (expression nested too deeply, item too long, functions expanding too far)",
    ),
    ("E0003", "number out of range (not a finite double-precision number)"),
    ("E0004", "constant arithmetic that is not finite (division by zero, overflow)"),
    ("E0101", "unknown name (with a suggestion when one is close)"),
    ("E0102", "name defined twice"),
    ("E0103", "duplicate argument, parameter or slot"),
    ("E0104", "`let` defined in terms of itself"),
    ("E0105", "recursive `fn`, or functions nested too deeply"),
    ("E0106", "built-in name redefined or used as a name"),
    ("E0201", "wrong number of arguments"),
    ("E0204", "calling something that is not a function"),
    ("E0205", "using a function, form or scheme as a value"),
    ("E0206", "`inf` outside a parameter range"),
    ("E0207", "a vector literal `[a, b]` or a component `x[1]` outside a problem"),
    ("E0301", "shape mismatch (a vector or tensor where another shape is needed)"),
    ("E0302", "wrong dimension: a vector's length or a component that does not fit the problem's dimension"),
    ("E0303", "exponent not a constant (an integer from -64 to 64 or a real number written in the file)"),
    ("E0304", "integrand not a scalar"),
    ("E0401", "integrand does not depend on the test function"),
    ("E0402", "test function inside a nonlinear function"),
    ("E0403", "test function in a denominator"),
    ("E0404", "test function multiplied by itself"),
    ("E0405", "form not linear in the test function (a term without it)"),
    ("E0406", "`prev` outside a form (a functional or a problem's expression has no previous time level)"),
    (
        "E0407",
        "`derivative(e, u, d)` with respect to something that is not a field of the form or an argument of the function",
    ),
    ("E0408", "`opposite` outside a facet integral (only a contact pair's surface has a facing side)"),
    ("E0409", "a volume integral in a contact pair's law (a file that reads `opposite`)"),
    ("E0410", "`int(REGION, both_sides)` in a law that reads no facing side (not a contact pair's law)"),
    ("E0411", "a contact pair's law with `both_sides` in some integrals and not in others"),
    ("E0501", "`n` or `h` in a volume integral"),
    ("E0502", "derivative of something that has none"),
    ("E0503", "form needs a quadrature degree above the cap (20)"),
    ("E0504", "quadrature degree not an integer from 0 to 20"),
    ("E0601", "parameter default outside its range"),
    ("E0602", "empty parameter range"),
    ("E0603", "parameter default or bound not a finite constant"),
    ("E0701", "missing import"),
    ("E0702", "import cycle"),
    ("E0802", "scheme: solving a relation divides by a coefficient that can vanish in the parameter ranges"),
    ("E0803", "scheme: items outside the `stage` blocks of a multi-stage scheme"),
    ("E0804", "scheme: a stage with two unknowns or two residuals"),
    ("E0805", "scheme: no state, no stage, or a stage without unknown or residual"),
    ("E0806", "scheme: a state gets no new value"),
    ("E0807", "scheme: a `let` that is not a scalar"),
    ("E0808", "scheme: `initial` solves for something that is not a state"),
    ("E0809", "scheme: a residual that does not depend on its unknown"),
    ("E0810", "scheme: a quantity related twice, or one already known"),
    ("E0811", "scheme: as many relations as new quantities besides the unknown are needed"),
    ("E0812", "scheme: a relation that determines no new quantity"),
    ("E0813", "scheme: a slot applied outside a residual, or a residual side not a sum of slot applications"),
    ("E0814", "scheme: a relation that is not affine in the time levels"),
    ("E0816", "scheme: a call to a name that is not one of its slots (`uses`)"),
    ("E0817", "scheme: a slot that is never applied"),
    ("E0818", "scheme: a stage time that is not finite for some parameter values"),
    ("E0819", "scheme: an unknown claim, or one that is not a function of the parameters"),
    ("E0820", "scheme: a state read at the start of a step that nothing sets at the start of the run"),
    ("E0821", "scheme: an energy claim its derived energy identity refutes"),
    ("E0822", "scheme: `emit --stage energy` derives no energy identity for it"),
    ("E0823", "scheme: more than one `estimate`"),
    ("E0824", "scheme: an `estimate` that is a scalar, not a combination of the step's levels"),
    ("E0825", "scheme: an `estimate` that reads nothing the step computes"),
    ("E0901", "problem: no mesh"),
    ("E0905", "problem: a Dirichlet condition on a contact region"),
    ("E0906", "problem: a `set` name that more than one file in use declares (qualify it: `material.rho`)"),
    ("E0907", "problem: a `neumann` load on a Dirichlet or contact region"),
    ("W0001", "unused parameter (warning)"),
    ("W0002", "a scheme `let` hides another name (warning)"),
    ("W0003", "a `fn` or `form` argument hides a name of the file (warning)"),
    ("W0004", "problem: a coef set that no file in use reads (warning)"),
    ("W0005", "scheme: a state (other than the displacement and `v`) that is never read (warning)"),
    ("W0006", "a tangent divides by an expression that is zero where pos/neg clips it: 0/0 there (warning)"),
    ("W0007", "scheme: an energy claim no energy identity can be derived for: verify only samples it (warning)"),
];

/// Codes reported when a problem is bound to the files of a run (the facade's bad-input corpus
/// exercises them; the compiler's own corpus cannot, as the files in use are not known there).
pub const BINDING_CODES: &[&str] = &["E0906", "W0004"];

/// Codes a stage other than `check` reports (`emit --stage energy`; the facade's bad-input
/// corpus exercises them).
pub const STAGE_CODES: &[&str] = &["E0822"];

/// The meaning of a diagnostic code, from [`CODES`].
pub fn describe(code: &str) -> Option<&'static str> {
    CODES.iter().find(|(c, _)| *c == code).map(|(_, m)| *m)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    Error,
    Warning,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Label {
    pub span: Span,
    pub message: String,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Diagnostic {
    pub severity: Severity,
    pub code: &'static str,
    pub message: String,
    pub primary: Label,
    pub secondary: Vec<Label>,
    pub notes: Vec<String>,
    pub help: Option<String>,
}

impl Diagnostic {
    /// An error; `code` must be listed in [`CODES`] (checked in debug builds).
    pub fn error(code: &'static str, message: impl Into<String>, span: Span, label: impl Into<String>) -> Self {
        debug_assert!(describe(code).is_some(), "diagnostic code {code} is not in diagnostic::CODES");
        Diagnostic {
            severity: Severity::Error,
            code,
            message: message.into(),
            primary: Label { span, message: label.into() },
            secondary: Vec::new(),
            notes: Vec::new(),
            help: None,
        }
    }

    /// A warning; `code` must be listed in [`CODES`] (checked in debug builds).
    pub fn warning(code: &'static str, message: impl Into<String>, span: Span, label: impl Into<String>) -> Self {
        Diagnostic { severity: Severity::Warning, ..Diagnostic::error(code, message, span, label) }
    }

    pub fn with_label(mut self, span: Span, message: impl Into<String>) -> Self {
        self.secondary.push(Label { span, message: message.into() });
        self
    }

    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// Rendered as text without colour: `error[E0101]: ...`, `--> file:line:col`, the source
    /// line, a caret under the span, labels, notes and help.
    pub fn render(&self, sources: &SourceMap) -> String {
        let severity = match self.severity {
            Severity::Error => cs::Severity::Error,
            Severity::Warning => cs::Severity::Warning,
        };
        let mut labels = vec![
            cs::Label::primary(self.primary.span.file, self.primary.span.start..self.primary.span.end)
                .with_message(&self.primary.message),
        ];
        for l in &self.secondary {
            labels.push(cs::Label::secondary(l.span.file, l.span.start..l.span.end).with_message(&l.message));
        }
        let mut notes = self.notes.clone();
        if let Some(help) = &self.help {
            notes.push(format!("help: {help}"));
        }
        let diag = cs::Diagnostic::new(severity)
            .with_code(self.code)
            .with_message(&self.message)
            .with_labels(labels)
            .with_notes(notes);
        let config = term::Config::default();
        term::emit_into_string(&config, &sources.files, &diag).unwrap_or_else(|e| {
            format!(
                "{}[{}]: {} (could not render source: {e})\n",
                severity_word(self.severity),
                self.code,
                self.message
            )
        })
    }
}

/// A diagnostic for a reader other than a terminal (the Python API, an editor): its texts and
/// where its primary span starts and ends, as 1-based lines and columns (in characters), with
/// the rendering the command line prints.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Located {
    pub severity: Severity,
    pub code: &'static str,
    pub message: String,
    pub file: std::path::PathBuf,
    pub line: usize,
    pub column: usize,
    pub end_line: usize,
    pub end_column: usize,
    /// The primary span's label.
    pub label: String,
    pub notes: Vec<String>,
    pub help: Option<String>,
    pub rendered: String,
}

impl Diagnostic {
    /// The diagnostic with its position read off `sources`.
    pub fn locate(&self, sources: &SourceMap) -> Located {
        let span = self.primary.span;
        let known = span.file < sources.len();
        let at = |offset: usize| if known { sources.line_col(span.file, offset) } else { (0, 0) };
        let ((line, column), (end_line, end_column)) = (at(span.start), at(span.end));
        Located {
            severity: self.severity,
            code: self.code,
            message: self.message.clone(),
            file: if known { sources.path(span.file).to_path_buf() } else { Default::default() },
            line,
            column,
            end_line,
            end_column,
            label: self.primary.message.clone(),
            notes: self.notes.clone(),
            help: self.help.clone(),
            rendered: self.render(sources),
        }
    }
}

impl Severity {
    /// `error` or `warning`, as the rendering says it.
    pub fn word(self) -> &'static str {
        severity_word(self)
    }
}

fn severity_word(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
    }
}

/// Most diagnostics rendered per file: a file of a million broken lines must not print
/// hundreds of megabytes.
pub const MAX_PER_FILE: usize = 100;

/// Renders all diagnostics, errors and warnings in source order, with a final count line; past
/// [`MAX_PER_FILE`] of one file, one line says how many more there are.
pub fn render_all(diags: &[Diagnostic], sources: &SourceMap) -> String {
    let mut out = String::new();
    let mut shown: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for d in diags {
        let n = shown.entry(d.primary.span.file).or_default();
        *n += 1;
        if *n <= MAX_PER_FILE {
            out.push_str(&d.render(sources));
        }
    }
    let mut hidden: Vec<(usize, usize)> =
        shown.into_iter().filter(|&(_, n)| n > MAX_PER_FILE).map(|(f, n)| (f, n - MAX_PER_FILE)).collect();
    hidden.sort_unstable();
    for (file, n) in hidden {
        let name = if file < sources.len() { sources.path(file).display().to_string() } else { "?".into() };
        out.push_str(&format!("note: {n} more diagnostics in {name} not shown\n"));
    }
    let errors = diags.iter().filter(|d| d.is_error()).count();
    let warnings = diags.len() - errors;
    if errors > 0 {
        out.push_str(&format!("{errors} error(s), {warnings} warning(s)\n"));
    }
    out
}

/// Sorts by position and removes exact duplicates (a function body checked at two call sites
/// reports its mistake once).
pub fn normalize(diags: &mut Vec<Diagnostic>) {
    diags.sort_by(|a, b| {
        (a.primary.span.file, a.primary.span.start, a.severity, a.code).cmp(&(
            b.primary.span.file,
            b.primary.span.start,
            b.severity,
            b.code,
        ))
    });
    diags.dedup_by(|a, b| a.code == b.code && a.primary.span == b.primary.span && a.message == b.message);
}

#[cfg(test)]
mod tests {
    use super::CODES;

    #[test]
    fn a_located_diagnostic_points_at_its_span_in_lines_and_characters() {
        // Two-byte characters before the mistake: columns count characters, not bytes.
        let text = "// é é é\nparam a = 1 in [0, 2]\nform m(u; v) = int(Omega) aa * dot(u, v)\n";
        let path = std::path::Path::new("located.wf");
        let Err((diags, sources)) = crate::check_text(path, text, &crate::MemLoader::default()) else {
            panic!("the file should not check")
        };
        let d = diags.iter().find(|d| d.code == "E0101").expect("an unknown name");
        let at = d.locate(&sources);
        assert_eq!((at.line, at.column, at.end_line, at.end_column), (3, 27, 3, 29));
        let line = text.lines().nth(at.line - 1).unwrap();
        let chars: String = line.chars().skip(at.column - 1).take(at.end_column - at.column).collect();
        assert_eq!(chars, "aa");
        assert_eq!(at.file, path);
        assert!(at.rendered.contains("located.wf:3:27"), "{}", at.rendered);
        let failure = crate::Failure::of(&diags, &sources);
        assert_eq!(failure.diagnostics.len(), diags.len());
        assert_eq!(failure.rendered, super::render_all(&diags, &sources));
    }

    #[test]
    fn the_catalogue_is_sorted_and_has_no_duplicates() {
        for w in CODES.windows(2) {
            assert!(w[0].0 < w[1].0, "{} before {}", w[0].0, w[1].0);
        }
        for (code, meaning) in CODES {
            assert!(code.len() == 5 && (code.starts_with('E') || code.starts_with('W')), "{code}");
            assert!(!meaning.is_empty() && !meaning.contains('\n'), "{code}");
        }
    }
}
