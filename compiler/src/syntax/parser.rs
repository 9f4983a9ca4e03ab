//! Text → AST. The file is split into chunks at item keywords (outside comments and braces) and
//! each chunk is parsed on its own, so one syntax error does not hide the others.

use pest::Parser as _;
use pest::iterators::Pair;
use pest::pratt_parser::{Assoc, Op, PrattParser};
use std::sync::LazyLock;

use super::ast::*;
use crate::diagnostic::Diagnostic;
use crate::source::{FileId, Span};

#[derive(pest_derive::Parser)]
#[grammar = "syntax/grammar.pest"]
struct WfParser;

const ITEM_KEYWORDS: &[&str] = &["import", "param", "coef", "let", "fn", "form", "functional", "scheme", "problem"];

/// Deepest nesting of parentheses accepted; deeper input is refused before parsing, so that
/// neither the parser nor the recursive checks can exhaust the stack.
pub const MAX_NESTING: usize = 64;
/// Most operators accepted in one item, for the same reason (left-deep sums).
pub const MAX_OPERATORS: usize = 1000;

static PRATT: LazyLock<PrattParser<Rule>> = LazyLock::new(|| {
    PrattParser::new()
        .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
        .op(Op::infix(Rule::mul, Assoc::Left) | Op::infix(Rule::div, Assoc::Left))
        .op(Op::prefix(Rule::neg))
        .op(Op::infix(Rule::pow, Assoc::Right))
        .op(Op::postfix(Rule::index))
});

/// Parses one file. Returns the items that parsed and one diagnostic per broken chunk.
pub fn parse(file: FileId, text: &str) -> (File, Vec<Diagnostic>) {
    pest::set_error_detail(true);
    let mut out = File::default();
    let mut diags = Vec::new();
    let (chunks, open_comment) = chunks(text);
    if let Some(at) = open_comment {
        diags.push(
            Diagnostic::error(
                "E0001",
                "unterminated comment",
                Span::new(file, at, at + 2),
                "this `/*` is never closed",
            )
            .with_help("close it with `*/`, or use `//` for a line comment"),
        );
    }
    for (start, end) in chunks {
        let chunk = &text[start..end];
        if let Some(d) = nesting_error(file, chunk, start) {
            diags.push(d);
            note_broken_name(chunk, &mut out.broken_names);
            continue;
        }
        match WfParser::parse(Rule::chunk, chunk) {
            Ok(mut pairs) => {
                let b = Builder { file, offset: start };
                let chunk_pair = pairs.next().expect("chunk rule always yields one pair");
                for p in chunk_pair.into_inner() {
                    if p.as_rule() != Rule::EOI {
                        let item_text = p.as_str();
                        match b.item(p) {
                            Ok(item) => out.items.push(item),
                            Err(d) => {
                                // An item that parsed but was refused (a number out of range,
                                // two unknowns) still declares its name.
                                diags.push(*d);
                                note_broken_name(item_text, &mut out.broken_names);
                            }
                        }
                    }
                }
            }
            Err(e) => {
                diags.push(syntax_error(file, chunk, start, &e));
                note_broken_name(chunk, &mut out.broken_names);
            }
        }
    }
    (out, diags)
}

/// Byte ranges of the chunks: boundaries at item keywords that start a line, outside comments,
/// strings and braces; and where a `/*` comment that never ends starts (the chunks stop there).
fn chunks(text: &str) -> (Vec<(usize, usize)>, Option<usize>) {
    let bytes = text.as_bytes();
    let mut starts = vec![0];
    let (mut i, mut depth, mut line_start) = (0, 0i64, true);
    while i < bytes.len() {
        let c = bytes[i];
        if bytes[i..].starts_with(b"//") {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        if bytes[i..].starts_with(b"/*") {
            let open = i;
            i += 2;
            while i < bytes.len() && !bytes[i..].starts_with(b"*/") {
                i += 1;
            }
            if i >= bytes.len() {
                starts.push(open);
                return (starts.windows(2).map(|w| (w[0], w[1])).collect(), Some(open));
            }
            i += 2;
            line_start = false;
            continue;
        }
        match c {
            b'\n' => line_start = true,
            b' ' | b'\t' | b'\r' => {}
            _ => {
                if line_start && depth == 0 && i > 0 && starts_item(&text[i..]) {
                    starts.push(i);
                }
                match c {
                    b'{' => depth += 1,
                    b'}' => depth -= 1,
                    _ => {}
                }
                line_start = false;
            }
        }
        i += 1;
    }
    starts.push(text.len());
    (starts.windows(2).map(|w| (w[0], w[1])).collect(), None)
}

fn starts_item(rest: &str) -> bool {
    ITEM_KEYWORDS.iter().any(|k| {
        rest.starts_with(k) && rest[k.len()..].chars().next().is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_'))
    })
}

fn nesting_error(file: FileId, chunk: &str, offset: usize) -> Option<Diagnostic> {
    let operators = chunk.bytes().filter(|b| b"+-*/^,".contains(b)).count();
    if operators > MAX_OPERATORS {
        let span = Span::new(file, offset, offset + chunk.find('\n').unwrap_or(chunk.len()));
        return Some(
            Diagnostic::error(
                "E0002",
                "item too long",
                span,
                format!("more than {MAX_OPERATORS} operators in one item"),
            )
            .with_help("split it into several `let` or `fn` items"),
        );
    }
    let mut depth = 0usize;
    for (i, c) in chunk.char_indices() {
        match c {
            '(' | '[' | '{' => depth += 1,
            ')' | ']' | '}' => depth = depth.saturating_sub(1),
            _ => {}
        }
        if depth > MAX_NESTING {
            let span = Span::new(file, offset + i, offset + i + 1);
            return Some(
                Diagnostic::error(
                    "E0002",
                    "expression nested too deeply",
                    span,
                    format!("more than {MAX_NESTING} levels of brackets"),
                )
                .with_help("name intermediate results with `let` or `fn`"),
            );
        }
    }
    None
}

/// Remembers the name a broken item would have declared (`param NAME`, `fn NAME`, ...).
fn note_broken_name(chunk: &str, names: &mut Vec<String>) {
    let mut words = chunk
        .lines()
        .map(str::trim)
        .filter(|l| !l.starts_with("//"))
        .flat_map(|l| l.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '\'')))
        .filter(|w| !w.is_empty());
    if let (Some(_kw), Some(name)) = (words.next(), words.next()) {
        names.push(name.to_string());
    }
}

fn syntax_error(file: FileId, chunk: &str, offset: usize, e: &pest::error::Error<Rule>) -> Diagnostic {
    let mut pos = match e.location {
        pest::error::InputLocation::Pos(p) => p,
        pest::error::InputLocation::Span((s, _)) => s,
    };
    let mut rules: Vec<Rule> = Vec::new();
    let mut tokens: Vec<String> = Vec::new();
    if let pest::error::ErrorVariant::ParsingError { positives, .. } = &e.variant {
        rules.extend(positives);
    }
    // With error detail on, pest also records the furthest point any alternative reached,
    // which is where the mistake is.
    if let Some(attempts) = e.parse_attempts()
        && attempts.max_position >= pos
    {
        if attempts.max_position > pos {
            rules.clear();
        }
        pos = attempts.max_position;
        for stack in &attempts.call_stacks {
            rules.extend(stack.deepest.get_rule().copied());
            rules.extend(stack.parent);
        }
        tokens.extend(attempts.expected_tokens().iter().map(|t| t.to_string()));
    }
    let mut expected: Vec<String> = rules.iter().filter_map(|r| rule_name(*r)).map(str::to_string).collect();
    let has = |what: &str, list: &[String]| list.iter().any(|e| e == what);
    let expression = has("an expression", &expected);
    let operator = has("an operator", &expected);
    for t in tokens {
        let punctuation = t.chars().all(|c| c.is_ascii_punctuation());
        let part_of_expression = expression && matches!(t.as_str(), "(" | "[" | "-" | "_" | ".");
        let part_of_operator = operator && matches!(t.as_str(), "+" | "-" | "*" | "/" | "^" | "[");
        if punctuation
            && !part_of_expression
            && !part_of_operator
            && !matches!(t.as_str(), "//" | "/*" | "*/" | "\"" | "." | "_")
        {
            expected.push(format!("`{t}`"));
        }
    }
    if expression {
        expected.retain(|e| e != "a name" && e != "a number");
    }
    // Redundant alternatives: a new item may always follow a complete one; the sign and
    // `int(` tokens are spelled out by the integral rule.
    const ITEM: &str = "an item (`import`, `param`, `coef`, `let`, `fn`, `form`)";
    if expected.len() > 1 {
        expected.retain(|e| e != ITEM);
    }
    if has("an integral `int(REGION) ...`", &expected) {
        expected.retain(|e| !matches!(e.as_str(), "`+`" | "`-`" | "`+` or `-`" | "`int(REGION)`"));
    }
    expected.sort();
    expected.dedup();
    // A failure at the end of the chunk is a missing continuation: point just after the last
    // token of the item rather than at the next item.
    let content_end = content_end(chunk);
    let at_end = pos >= content_end;
    let pos = pos.min(content_end);
    let found = if at_end { "" } else { found_token(&chunk[pos..]) };
    let span = Span::new(file, offset + pos, offset + pos + found.len());
    let found_text = if at_end { "the end of the item".to_string() } else { format!("`{found}`") };
    let message = if expected.is_empty() {
        format!("unexpected {found_text}")
    } else {
        format!("expected {}, found {found_text}", join_or(&expected))
    };
    let mut d = Diagnostic::error("E0001", "syntax error", span, message);
    let keyword = chunk.split_whitespace().next().unwrap_or("");
    if found == "=" && expected.iter().any(|e| e == "`(`") {
        d = d.with_help("a function needs its parameters: `fn name(arg) = ...`");
    } else if keyword == "coef" && found == "=" {
        d = d.with_help(
            "a coef is case data supplied at run time (`coef g`, `coef nc: vector`); use `param` for a number",
        );
    } else if found == ":" {
        d = d.with_help("declare case data with `coef NAME: vector`; parameters are `param NAME = VALUE`");
    }
    d
}

/// Offset just after the last character of the chunk that is not whitespace or a comment.
fn content_end(chunk: &str) -> usize {
    let mut end = 0;
    let mut in_line_comment = false;
    let mut in_block = false;
    let bytes = chunk.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if in_line_comment {
            if bytes[i] == b'\n' {
                in_line_comment = false;
            }
        } else if in_block {
            if bytes[i..].starts_with(b"*/") {
                in_block = false;
                i += 1;
            }
        } else if bytes[i..].starts_with(b"//") {
            in_line_comment = true;
        } else if bytes[i..].starts_with(b"/*") {
            in_block = true;
            i += 1;
        } else if !bytes[i].is_ascii_whitespace() {
            end = i + 1;
        }
        i += 1;
    }
    // Land on a character boundary.
    while !chunk.is_char_boundary(end) {
        end += 1;
    }
    end
}

/// A string literal's content.
fn unquote(s: &str) -> String {
    s[1..s.len() - 1].to_string()
}

fn join_or(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [a] => a.clone(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

/// The token at the start of `rest`: an identifier, a number, or one character.
fn found_token(rest: &str) -> &str {
    let rest_trim = rest;
    let mut chars = rest_trim.char_indices();
    match chars.next() {
        None => "",
        Some((_, c)) if c.is_ascii_alphanumeric() || c == '_' || c == '.' => {
            let end = rest_trim
                .char_indices()
                .find(|(_, c)| !(c.is_ascii_alphanumeric() || *c == '_' || *c == '.' || *c == '\''))
                .map_or(rest_trim.len(), |(i, _)| i);
            &rest_trim[..end]
        }
        Some((_, c)) => &rest_trim[..c.len_utf8()],
    }
}

fn rule_name(r: Rule) -> Option<&'static str> {
    Some(match r {
        Rule::ident => "a name",
        Rule::role => "a role (`scheme`, `contact`, `material`, `forms`)",
        Rule::number => "a number",
        Rule::expr | Rule::call | Rule::neg => "an expression",
        Rule::add | Rule::sub | Rule::mul | Rule::div | Rule::pow => "an operator",
        Rule::import
        | Rule::param
        | Rule::coef
        | Rule::let_decl
        | Rule::fn_decl
        | Rule::form_decl
        | Rule::functional_decl => "an item (`import`, `param`, `coef`, `let`, `fn`, `form`)",
        Rule::range => "`in RANGE`",
        Rule::lbound => "`[` or `(`",
        Rule::rbound => "`]` or `)`",
        Rule::shape => "`scalar`, `vector` or `tensor`",
        Rule::string | Rule::module_name => "a module name",
        Rule::sign => "`+` or `-`",
        Rule::integral => "`int(REGION)`",
        Rule::degree_arg => "`degree = K`",
        Rule::integrals => "an integral `int(REGION) ...`",
        Rule::form_args | Rule::ident_list => "argument names",
        Rule::state_decl
        | Rule::uses_decl
        | Rule::unknown_decl
        | Rule::new_decl
        | Rule::claim_decl
        | Rule::relate_decl
        | Rule::residual_decl
        | Rule::stage_block
        | Rule::initial_decl => {
            "a scheme item (`uses`, `state`, `unknown`, `new`, `relate`, `residual`, `stage`, `initial`, `let`, `claim`)"
        }
        Rule::scheme_params | Rule::scheme_param => "parameters",
        Rule::mesh_decl
        | Rule::region_decl
        | Rule::bind_decl
        | Rule::set_decl
        | Rule::coef_def
        | Rule::obstacle_decl
        | Rule::initial_field
        | Rule::dirichlet_decl
        | Rule::series_decl
        | Rule::observe_decl
        | Rule::summary_decl
        | Rule::plot_decl
        | Rule::run_decl
        | Rule::quadrature_decl
        | Rule::reference_decl => {
            "a problem item (`mesh`, `region`, `bind`, `set`, `coef`, `obstacle`, `initial`, `dirichlet`, `series`, `observe`, `summary`, `plot`, `run`, `quadrature`, `reference`, `let`)"
        }
        Rule::named_arg | Rule::assignments => "`NAME = VALUE`",
        Rule::region_source | Rule::group_source | Rule::boundary_source => "`group \"NAME\"` or `boundary where ...`",
        Rule::compare => "a comparison (`<`, `<=`, `>`, `>=`)",
        Rule::vector => "an expression",
        _ => return None,
    })
}

struct Builder {
    file: FileId,
    offset: usize,
}

impl Builder {
    /// The span of a pair without the whitespace pest may have consumed at its end.
    fn span(&self, p: &Pair<Rule>) -> Span {
        let s = p.as_span();
        let trimmed = s.as_str().trim_end().len();
        Span::new(self.file, self.offset + s.start(), self.offset + s.start() + trimmed)
    }

    fn ident(&self, p: Pair<Rule>) -> Ident {
        Ident { name: p.as_str().to_string(), span: self.span(&p) }
    }

    fn item(&self, p: Pair<Rule>) -> Result<Item, Box<Diagnostic>> {
        let span = self.span(&p);
        let rule = p.as_rule();
        let mut it = p.into_inner();
        let mut next = || it.next().expect("grammar guarantees the child");
        Ok(match rule {
            Rule::import => {
                let target = next();
                let path = match target.as_rule() {
                    Rule::string => {
                        let s = target.as_str();
                        s[1..s.len() - 1].to_string()
                    }
                    _ => format!("{}.wf", target.as_str()),
                };
                Item::Import { path, span }
            }
            Rule::param => {
                let name = self.ident(next());
                let default = self.expr(next())?;
                let mut range = None;
                for r in it {
                    range = Some(self.range(r)?);
                }
                Item::Param { name, default, range, span }
            }
            Rule::coef => {
                let name = self.ident(next());
                let shape = match it.next().map(|s| s.as_str().to_string()) {
                    None => Shape::Scalar,
                    Some(s) if s == "vector" => Shape::Vector,
                    Some(s) if s == "tensor" => Shape::Tensor,
                    Some(_) => Shape::Scalar,
                };
                Item::Coef { name, shape, span }
            }
            Rule::let_decl => {
                let name = self.ident(next());
                let value = self.expr(next())?;
                Item::Let { name, value, span }
            }
            Rule::fn_decl => {
                let name = self.ident(next());
                let mut params = Vec::new();
                let mut body = None;
                for q in it {
                    match q.as_rule() {
                        Rule::ident_list => params = q.into_inner().map(|i| self.ident(i)).collect(),
                        _ => body = Some(self.expr(q)?),
                    }
                }
                Item::Fn { name, params, body: body.expect("fn has a body"), span }
            }
            Rule::form_decl => {
                let name = self.ident(next());
                let args = next();
                let mut fields = Vec::new();
                let mut test = None;
                for a in args.into_inner() {
                    match a.as_rule() {
                        Rule::ident_list => fields = a.into_inner().map(|i| self.ident(i)).collect(),
                        _ => test = Some(self.ident(a)),
                    }
                }
                let integrals = self.integrals(next())?;
                Item::Form { name, fields, test: Some(test.expect("form has a test function")), integrals, span }
            }
            Rule::scheme_decl => self.scheme(span, next(), it)?,
            Rule::problem_decl => Item::Problem(Box::new(self.problem(span, next(), it)?)),
            Rule::functional_decl => {
                let name = self.ident(next());
                let mut fields = Vec::new();
                let mut integrals = Vec::new();
                for q in it {
                    match q.as_rule() {
                        Rule::ident_list => fields = q.into_inner().map(|i| self.ident(i)).collect(),
                        _ => integrals = self.integrals(q)?,
                    }
                }
                Item::Form { name, fields, test: None, integrals, span }
            }
            r => unreachable!("not an item: {r:?}"),
        })
    }

    fn scheme(
        &self,
        span: Span,
        name: Pair<Rule>,
        rest: pest::iterators::Pairs<Rule>,
    ) -> Result<Item, Box<Diagnostic>> {
        let name = self.ident(name);
        let (mut params, mut states, mut initial, mut lets) = (Vec::new(), Vec::new(), None, Vec::new());
        let mut uses = Vec::new();
        let mut claims = Vec::new();
        let mut stages: Vec<Stage> = Vec::new();
        // Items outside `stage` blocks form one implicit stage at t + dt.
        let mut implicit = Stage::default();
        for p in rest {
            match p.as_rule() {
                Rule::scheme_params => params = self.params(p.into_inner())?,
                Rule::uses_decl => {
                    let list = p.into_inner().next().expect("slot names");
                    uses.extend(list.into_inner().map(|i| self.ident(i)));
                }
                Rule::state_decl => {
                    let list = p.into_inner().next().expect("state names");
                    states.extend(list.into_inner().map(|i| self.ident(i)));
                }
                Rule::initial_decl => {
                    let span = self.span(&p);
                    let mut it = p.into_inner();
                    let unknown = self.ident(it.next().expect("initial unknown"));
                    let lhs = self.expr(it.next().expect("lhs"))?;
                    let rhs = self.expr(it.next().expect("rhs"))?;
                    initial = Some(Initial { unknown, residual: Residual { lhs, rhs, span }, span });
                }
                Rule::stage_block => {
                    let span = self.span(&p);
                    let mut stage = Stage { span: Some(span), ..Stage::default() };
                    for q in p.into_inner() {
                        match q.as_rule() {
                            Rule::ident => stage.name = Some(self.ident(q)),
                            Rule::expr => stage.at = Some(self.expr(q)?),
                            _ => self.stage_item(&mut stage, q)?,
                        }
                    }
                    stages.push(stage);
                }
                Rule::let_decl => {
                    let mut it = p.into_inner();
                    let name = self.ident(it.next().expect("let name"));
                    lets.push((name, self.expr(it.next().expect("let value"))?));
                }
                Rule::claim_decl => {
                    let mut it = p.into_inner();
                    let name = self.ident(it.next().expect("claim name"));
                    claims.push((name, self.expr(it.next().expect("claim value"))?));
                }
                _ => self.stage_item(&mut implicit, p)?,
            }
        }
        let implicit_used = implicit.unknown.is_some() || !implicit.relates.is_empty() || implicit.residual.is_some();
        if implicit_used {
            if stages.is_empty() {
                stages.push(implicit);
            } else {
                let at = implicit
                    .relates
                    .first()
                    .map(|r| r.span)
                    .or(implicit.residual.as_ref().map(|r| r.span))
                    .unwrap_or(span);
                let d = Diagnostic::error(
                    "E0803",
                    "scheme items outside the `stage` blocks",
                    at,
                    "put this inside a stage",
                )
                .with_note("a scheme is either one implicit stage or a list of `stage NAME at TIME { ... }` blocks");
                return Err(Box::new(d));
            }
        }
        Ok(Item::Scheme { name, params, uses, states, lets, initial, claims, stages, span })
    }

    fn problem(
        &self,
        span: Span,
        name: Pair<Rule>,
        rest: pest::iterators::Pairs<Rule>,
    ) -> Result<Problem, Box<Diagnostic>> {
        let mut pb = Problem {
            name: self.ident(name),
            params: Vec::new(),
            mesh: Vec::new(),
            regions: Vec::new(),
            binds: Vec::new(),
            sets: Vec::new(),
            coefs: Vec::new(),
            obstacles: Vec::new(),
            initial: Vec::new(),
            dirichlet: Vec::new(),
            series: Vec::new(),
            summary: Vec::new(),
            plots: Vec::new(),
            run: Vec::new(),
            run_static: None,
            quadrature: Vec::new(),
            reference: None,
            reference_args: Vec::new(),
            lets: Vec::new(),
            span,
        };
        for p in rest {
            let span = self.span(&p);
            let rule = p.as_rule();
            let mut it = p.into_inner();
            let mut next = || it.next().expect("grammar guarantees the child");
            match rule {
                Rule::scheme_params => pb.params = self.params(it)?,
                Rule::mesh_decl => {
                    let q = next();
                    pb.mesh.push(match q.as_rule() {
                        Rule::string => MeshSource::File { path: unquote(q.as_str()), span: self.span(&q) },
                        _ => MeshSource::Generator(self.named_call(q)?),
                    });
                }
                Rule::region_decl => {
                    let name = self.ident(next());
                    let mut sources = Vec::new();
                    for q in it {
                        let q = q.into_inner().next().expect("region source");
                        let qspan = self.span(&q);
                        sources.push(match q.as_rule() {
                            Rule::group_source => {
                                let mut parts = q.into_inner();
                                let name = unquote(parts.next().expect("group name").as_str());
                                let conditions = parts.map(|c| self.comparison(c)).collect::<Result<Vec<_>, _>>()?;
                                RegionSource::Group { name, conditions, span: qspan }
                            }
                            _ => {
                                let conditions =
                                    q.into_inner().map(|c| self.comparison(c)).collect::<Result<Vec<_>, _>>()?;
                                RegionSource::Boundary { conditions, span: qspan }
                            }
                        });
                    }
                    pb.regions.push(RegionDecl { name, sources, span });
                }
                Rule::bind_decl => {
                    for q in it {
                        let span = self.span(&q);
                        let mut parts = q.into_inner();
                        let role = self.ident(parts.next().expect("role"));
                        let target = parts.next().expect("target");
                        let is_path = target.as_rule() == Rule::string;
                        let target = if is_path { unquote(target.as_str()) } else { target.as_str().to_string() };
                        pb.binds.push(Bind { role, target, is_path, span });
                    }
                }
                Rule::set_decl => pb.sets.extend(self.assignments(next())?),
                Rule::run_decl => {
                    let q = next();
                    if q.as_rule() == Rule::run_static {
                        pb.run_static = Some(self.span(&q));
                    } else {
                        pb.run.extend(self.assignments(q)?);
                    }
                }
                Rule::quadrature_decl => pb.quadrature.extend(self.assignments(next())?),
                Rule::coef_def => pb.coefs.push(self.defined(span, next(), it.next())?),
                Rule::initial_field => pb.initial.push(self.defined(span, next(), it.next())?),
                Rule::series_decl => pb.series.push((self.defined(span, next(), it.next())?, true)),
                Rule::observe_decl => pb.series.push((self.defined(span, next(), it.next())?, false)),
                Rule::summary_decl => pb.summary.push(self.defined(span, next(), it.next())?),
                Rule::let_decl => pb.lets.push(self.defined(span, next(), it.next())?),
                Rule::obstacle_decl => {
                    let shape = self.named_call(next())?;
                    let region = it.next().map(|q| self.ident(q));
                    pb.obstacles.push(Obstacle { shape, region, span });
                }
                Rule::dirichlet_decl => {
                    let target = next();
                    let on = if target.as_rule() == Rule::nearest_node {
                        let span = self.span(&target);
                        HeldAt::Nearest { point: self.expr(target.into_inner().next().expect("a point"))?, span }
                    } else {
                        HeldAt::Region(self.ident(target))
                    };
                    let field = self.ident(next());
                    let mut rest = next();
                    let mut component = None;
                    if rest.as_rule() == Rule::index {
                        component = Some(self.expr(rest.into_inner().next().expect("index expression"))?);
                        rest = next();
                    }
                    let value = self.expr(rest)?;
                    pb.dirichlet.push(Dirichlet { on, field, component, value, span });
                }
                Rule::plot_decl => {
                    let title = unquote(next().as_str());
                    let columns = next().into_inner().map(|i| self.ident(i)).collect();
                    pb.plots.push(Plot { title, columns, span });
                }
                Rule::reference_decl => {
                    let target = next();
                    let (name, args) = if target.as_rule() == Rule::call_named {
                        let call = self.named_call(target)?;
                        (call.name, call.args)
                    } else {
                        (self.ident(target), Vec::new())
                    };
                    if let Some(prev) = &pb.reference {
                        let d = Diagnostic::error("E0102", "a problem names one reference", name.span, "second one")
                            .with_label(prev.span, "first one");
                        return Err(Box::new(d));
                    }
                    pb.reference = Some(name);
                    pb.reference_args = args;
                }
                r => unreachable!("not a problem item: {r:?}"),
            }
        }
        Ok(pb)
    }

    /// The params of a scheme or a problem: `name = default in RANGE, ...`.
    fn params(&self, list: pest::iterators::Pairs<Rule>) -> Result<Vec<SchemeParam>, Box<Diagnostic>> {
        list.map(|q| {
            let span = self.span(&q);
            let mut it = q.into_inner();
            let name = self.ident(it.next().expect("param name"));
            let default = self.expr(it.next().expect("param default"))?;
            let range = it.next().map(|r| self.range(r)).transpose()?;
            Ok(SchemeParam { name, default, range, span })
        })
        .collect()
    }

    /// `name = expr` from its two pairs.
    fn defined(&self, span: Span, name: Pair<Rule>, value: Option<Pair<Rule>>) -> Result<Defined, Box<Diagnostic>> {
        let name = self.ident(name);
        let value = self.expr(value.expect("grammar guarantees the value"))?;
        Ok(Defined { name, value, span })
    }

    fn assignments(&self, p: Pair<Rule>) -> Result<Vec<Defined>, Box<Diagnostic>> {
        p.into_inner()
            .map(|q| {
                let span = self.span(&q);
                let mut it = q.into_inner();
                let name = it.next().expect("name");
                self.defined(span, name, it.next())
            })
            .collect()
    }

    fn named_call(&self, p: Pair<Rule>) -> Result<NamedCall, Box<Diagnostic>> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let name = self.ident(it.next().expect("callee"));
        let args = it
            .map(|q| {
                let mut parts = q.into_inner();
                let name = self.ident(parts.next().expect("argument name"));
                Ok(NamedArg { name, value: self.expr(parts.next().expect("argument value"))? })
            })
            .collect::<Result<Vec<_>, Box<Diagnostic>>>()?;
        Ok(NamedCall { name, args, span })
    }

    fn comparison(&self, p: Pair<Rule>) -> Result<Comparison, Box<Diagnostic>> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let lhs = self.expr(it.next().expect("lhs"))?;
        let op = match it.next().expect("comparison").as_str() {
            "<" => Compare::Less,
            "<=" => Compare::LessEqual,
            ">" => Compare::Greater,
            _ => Compare::GreaterEqual,
        };
        let rhs = self.expr(it.next().expect("rhs"))?;
        Ok(Comparison { lhs, op, rhs, span })
    }

    fn stage_item(&self, stage: &mut Stage, p: Pair<Rule>) -> Result<(), Box<Diagnostic>> {
        let span = self.span(&p);
        let rule = p.as_rule();
        let mut it = p.into_inner();
        match rule {
            Rule::let_decl => {
                let name = self.ident(it.next().expect("let name"));
                stage.lets.push((name, self.expr(it.next().expect("let value"))?));
            }
            Rule::unknown_decl => {
                let name = self.ident(it.next().expect("unknown name"));
                if let Some(prev) = &stage.unknown {
                    let d = Diagnostic::error("E0804", "a stage has one unknown", name.span, "second unknown")
                        .with_label(prev.span, "first unknown");
                    return Err(Box::new(d));
                }
                stage.unknown = Some(name);
            }
            Rule::new_decl => {
                let list = it.next().expect("new names");
                stage.news.extend(list.into_inner().map(|i| self.ident(i)));
            }
            Rule::relate_decl => {
                let name = self.ident(it.next().expect("relate name"));
                let value = self.expr(it.next().expect("relate value"))?;
                stage.relates.push(Relate { name, value, span });
            }
            Rule::residual_decl => {
                let lhs = self.expr(it.next().expect("lhs"))?;
                let rhs = self.expr(it.next().expect("rhs"))?;
                if let Some(prev) = &stage.residual {
                    let d = Diagnostic::error("E0804", "a stage has one residual", span, "second residual")
                        .with_label(prev.span, "first residual");
                    return Err(Box::new(d));
                }
                stage.residual = Some(Residual { lhs, rhs, span });
            }
            r => unreachable!("not a stage item: {r:?}"),
        }
        Ok(())
    }

    fn range(&self, p: Pair<Rule>) -> Result<Range, Box<Diagnostic>> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let lo_closed = it.next().map(|b| b.as_str() == "[").unwrap_or(true);
        let lo = self.expr(it.next().expect("range lower bound"))?;
        let hi = self.expr(it.next().expect("range upper bound"))?;
        let hi_closed = it.next().map(|b| b.as_str() == "]").unwrap_or(true);
        Ok(Range { lo, lo_closed, hi, hi_closed, span })
    }

    fn integrals(&self, p: Pair<Rule>) -> Result<Vec<Integral>, Box<Diagnostic>> {
        let mut out = Vec::new();
        let mut sign = 1.0;
        let mut sign_span: Option<Span> = None;
        for q in p.into_inner() {
            match q.as_rule() {
                Rule::sign => {
                    sign = if q.as_str() == "-" { -1.0 } else { 1.0 };
                    sign_span = Some(self.span(&q));
                }
                _ => {
                    let mut span = self.span(&q);
                    if let Some(s) = sign_span.take() {
                        span = s.to(span);
                    }
                    let mut it = q.into_inner();
                    let region = self.ident(it.next().expect("integral region"));
                    let mut next = it.next().expect("integrand");
                    let mut degree = None;
                    if next.as_rule() == Rule::degree_arg {
                        let number = next.into_inner().next().expect("degree");
                        let value = number.as_str().parse::<f64>().unwrap_or(f64::NAN);
                        degree = Some((value, self.span(&number)));
                        next = it.next().expect("integrand");
                    }
                    let integrand = self.expr(next)?;
                    out.push(Integral { sign, region, degree, integrand, span });
                    sign = 1.0;
                }
            }
        }
        Ok(out)
    }

    fn expr(&self, p: Pair<Rule>) -> Result<Expr, Box<Diagnostic>> {
        PRATT
            .map_primary(|q| self.primary(q))
            .map_prefix(|op, rhs| {
                let rhs = rhs?;
                let span = self.span(&op).to(rhs.span);
                Ok(Expr { kind: ExprKind::Neg(Box::new(rhs)), span })
            })
            .map_infix(|lhs, op, rhs| {
                let (lhs, rhs) = (lhs?, rhs?);
                let op = match op.as_rule() {
                    Rule::add => BinOp::Add,
                    Rule::sub => BinOp::Sub,
                    Rule::mul => BinOp::Mul,
                    Rule::div => BinOp::Div,
                    _ => BinOp::Pow,
                };
                let span = lhs.span.to(rhs.span);
                Ok(Expr { kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)), span })
            })
            .map_postfix(|lhs, op| {
                let lhs = lhs?;
                let span = lhs.span.to(self.span(&op));
                let index = self.expr(op.into_inner().next().expect("index expression"))?;
                Ok(Expr { kind: ExprKind::Index(Box::new(lhs), Box::new(index)), span })
            })
            .parse(p.into_inner())
    }

    fn primary(&self, p: Pair<Rule>) -> Result<Expr, Box<Diagnostic>> {
        let span = self.span(&p);
        Ok(match p.as_rule() {
            Rule::number => match p.as_str().parse::<f64>() {
                Ok(v) if v.is_finite() => Expr { kind: ExprKind::Number(v), span },
                _ => {
                    let d =
                        Diagnostic::error("E0003", "number out of range", span, "not a finite double-precision number");
                    return Err(Box::new(d));
                }
            },
            Rule::ident => Expr { kind: ExprKind::Name(self.ident(p)), span },
            Rule::call => {
                let mut it = p.into_inner();
                let name = self.ident(it.next().expect("callee"));
                let args = it.map(|a| self.expr(a)).collect::<Result<Vec<_>, _>>()?;
                Expr { kind: ExprKind::Call(name, args), span }
            }
            Rule::vector => {
                let items = p.into_inner().map(|a| self.expr(a)).collect::<Result<Vec<_>, _>>()?;
                Expr { kind: ExprKind::Vector(items), span }
            }
            Rule::expr => {
                // Parenthesised: keep the span of the parentheses' content.
                self.expr(p)?
            }
            r => unreachable!("not a primary: {r:?}"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_split_at_item_keywords_only() {
        let text = "param a = 1\n// let b = 2\nlet c = a\n  + 1\nfn f(x) = x\n";
        let (c, open) = chunks(text);
        assert_eq!(c.len(), 3);
        assert!(text[c[1].0..c[1].1].starts_with("let c"));
        assert_eq!(open, None);
    }

    #[test]
    fn an_unterminated_comment_is_reported_where_it_opens() {
        let text = "param a = 1\n/* never closed\nlet c = a\n";
        let (f, d) = parse(0, text);
        assert_eq!(d.len(), 1, "{d:?}");
        assert_eq!(d[0].code, "E0001");
        assert_eq!(d[0].primary.span.start, text.find("/*").unwrap());
        assert_eq!(f.items.len(), 1);
    }

    #[test]
    fn precedence_of_power_and_unary_minus() {
        let (f, d) = parse(0, "let a = -x^2 + 3*y/2");
        assert!(d.is_empty(), "{d:?}");
        let Item::Let { value, .. } = &f.items[0] else { panic!() };
        let ExprKind::Binary(BinOp::Add, lhs, _) = &value.kind else { panic!("{value:?}") };
        assert!(matches!(lhs.kind, ExprKind::Neg(_)));
    }

    #[test]
    fn integrand_stops_before_next_integral() {
        let (f, d) = parse(0, "form a(u; v) = int(Omega) dot(u, v) + 1 - int(G) dot(u,v)");
        assert!(d.is_empty(), "{d:?}");
        let Item::Form { integrals, .. } = &f.items[0] else { panic!() };
        assert_eq!(integrals.len(), 2);
        assert_eq!(integrals[1].sign, -1.0);
    }

    #[test]
    fn errors_in_two_items_are_both_reported() {
        let (f, d) = parse(0, "param a = \nlet b = 1\nfn g(x = x\n");
        assert_eq!(d.len(), 2);
        assert_eq!(f.items.len(), 1);
        assert_eq!(f.broken_names, vec!["a".to_string(), "g".to_string()]);
    }
}
