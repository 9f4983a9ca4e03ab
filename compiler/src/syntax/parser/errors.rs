//! Syntax errors in words: what was expected (the grammar's rules by name), what was found,
//! and input nested too deeply to parse.

use super::{MAX_NESTING, MAX_OPERATORS, Rule};
use crate::diagnostic::Diagnostic;
use crate::source::{FileId, Span};

pub(super) fn nesting_error(file: FileId, chunk: &str, offset: usize) -> Option<Diagnostic> {
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

pub(super) fn syntax_error(file: FileId, chunk: &str, offset: usize, e: &pest::error::Error<Rule>) -> Diagnostic {
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
    // A reserved word where a name was expected: the parser may have looked past it.
    let before = chunk[..pos].trim_end();
    let word_start = before.trim_end_matches(|c: char| c.is_ascii_alphanumeric() || c == '_').len();
    if has("a name", &expected) && RESERVED.contains(&&before[word_start..]) && !RESERVED.contains(&found) {
        let word = &before[word_start..];
        let span = Span::new(file, offset + word_start, offset + before.len());
        return Diagnostic::error(
            "E0001",
            "syntax error",
            span,
            format!("expected a name, found the reserved word `{word}`"),
        )
        .with_note(format!("`{word}` is a reserved word of the language: it cannot name anything"))
        .with_help(format!("choose another name (`{word}_`, say)"));
    }
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
    } else if has("a name", &expected) && RESERVED.contains(&found) {
        d = d
            .with_note(format!("`{found}` is a reserved word of the language: it cannot name anything"))
            .with_help(format!("choose another name (`{found}_`, say)"));
    }
    d
}

/// The language's keywords (grammar.pest's `keyword`), which no name may be.
const RESERVED: &[&str] = &[
    "import",
    "param",
    "coef",
    "let",
    "fn",
    "form",
    "functional",
    "int",
    "in",
    "scheme",
    "state",
    "unknown",
    "new",
    "claim",
    "estimate",
    "relate",
    "residual",
    "stage",
    "at",
    "initial",
    "uses",
    "problem",
    "mesh",
    "region",
    "group",
    "boundary",
    "where",
    "else",
    "and",
    "bind",
    "set",
    "obstacle",
    "on",
    "dirichlet",
    "series",
    "observe",
    "summary",
    "plot",
    "run",
    "quadrature",
    "reference",
    "expect",
    "within",
    "when",
    "or",
    "not",
    "neumann",
];

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
        Rule::both_sides => "`both_sides`",
        Rule::integrals => "an integral `int(REGION) ...`",
        Rule::form_args | Rule::ident_list => "argument names",
        Rule::state_decl
        | Rule::uses_decl
        | Rule::unknown_decl
        | Rule::new_decl
        | Rule::claim_decl
        | Rule::estimate_decl
        | Rule::relate_decl
        | Rule::residual_decl
        | Rule::stage_block
        | Rule::initial_decl => {
            "a scheme item (`uses`, `state`, `unknown`, `new`, `relate`, `residual`, `stage`, `initial`, `let`, `claim`, `estimate`)"
        }
        Rule::scheme_params | Rule::scheme_param => "parameters",
        Rule::mesh_decl
        | Rule::body_decl
        | Rule::contact_pair
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
        | Rule::expect_decl
        | Rule::plot_decl
        | Rule::run_decl
        | Rule::quadrature_decl
        | Rule::reference_decl => {
            "a problem item (`mesh`, `body`, `contact`, `region`, `bind`, `set`, `coef`, `obstacle`, `initial`, `dirichlet`, `series`, `observe`, `summary`, `expect`, `plot`, `run`, `quadrature`, `reference`, `let`)"
        }
        Rule::named_arg | Rule::assignments => "`NAME = VALUE`",
        Rule::region_source | Rule::group_source | Rule::boundary_source => "`group \"NAME\"` or `boundary where ...`",
        Rule::compare => "a comparison (`<`, `<=`, `>`, `>=`)",
        Rule::vector => "an expression",
        _ => return None,
    })
}

#[cfg(test)]
mod reserved_words {
    /// The reserved words named in messages are grammar.pest's keywords, all of them.
    #[test]
    fn are_the_grammar_s_keywords() {
        let grammar = include_str!("../grammar.pest");
        let rule = grammar.split("keyword    = @{").nth(1).and_then(|r| r.split("~ !ident_char").next()).unwrap();
        let mut words: Vec<&str> = rule.split('"').skip(1).step_by(2).collect();
        let mut reserved = super::RESERVED.to_vec();
        words.sort_unstable();
        reserved.sort_unstable();
        assert_eq!(words, reserved);
    }
}
