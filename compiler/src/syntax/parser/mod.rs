//! Text → AST. The file is split into chunks at item keywords (outside comments and braces) and
//! each chunk is parsed on its own, so one syntax error does not hide the others. `build` turns
//! the pest pairs of a chunk into items (`problem` those of a problem), `errors` words what
//! pest could not parse.

use pest::Parser as _;

use super::ast::File;
mod build;
mod errors;
mod problem;

use build::Builder;
use errors::{nesting_error, syntax_error};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::ast::*;

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
