//! The compiler never panics: random byte strings, truncations and random mutations of the
//! valid forms either compile (and then generate code that parses) or produce diagnostics.

use std::path::Path;

use proptest::prelude::*;
use signorini_compiler::{MemLoader, codegen, compile_text};

fn library() -> MemLoader {
    let mut loader = MemLoader::default();
    for entry in std::fs::read_dir("../forms").expect("forms/ exists") {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "wf") {
            let name = Path::new("forms").join(p.file_name().unwrap());
            loader = loader.with(name, std::fs::read_to_string(&p).unwrap());
        }
    }
    loader
}

/// Checks `text` as `forms/fuzz.wf`; if it passes, generates code, which must parse.
fn run(text: &str, loader: &MemLoader) {
    match compile_text(Path::new("forms/fuzz.wf"), text, loader) {
        Err(failure) => assert!(failure.rendered.contains("error["), "{failure}"),
        Ok(compiled) => {
            let opts =
                codegen::Options { runtime: "::rt".into(), module: "fuzz".into(), source_name: "fuzz.wf".into() };
            if let Err(e) = compiled.rust(&opts) {
                panic!("valid input generated bad code: {e}\ninput:\n{text}");
            }
        }
    }
}

const TOKENS: &[&str] = &[
    "(",
    ")",
    ",",
    ";",
    "+",
    "-",
    "*",
    "/",
    "^",
    "=",
    ":",
    "[",
    "]",
    "{",
    "}",
    "int(Omega)",
    "int(Gamma_C)",
    "u",
    "v",
    "n",
    "h",
    "x",
    "grad(",
    "dot(",
    "pos(",
    "neg(",
    "H(",
    "sqrt(",
    "sin(",
    "atan2(",
    "exp(",
    "ln(",
    "0",
    "1",
    "2.5",
    "1e308",
    "0/0",
    "-1",
    "inf",
    "param",
    "let",
    "fn",
    "form",
    "coef",
    "import",
    "import elasticity",
    "\n",
    " ",
    "//",
    "/*",
    "*/",
    "sigma(",
    "eps(",
    "gamma",
    "theta",
    "I",
    "tr(",
    "sym(",
    "'",
    "\"",
    "é",
];

fn sources() -> Vec<String> {
    ["elasticity", "contact_nitsche", "contact_penalty"]
        .iter()
        .map(|f| std::fs::read_to_string(format!("../forms/{f}.wf")).unwrap())
        .collect()
}

#[derive(Debug, Clone)]
enum Edit {
    Delete(usize, usize),
    Insert(usize, usize),
    Truncate(usize),
    Duplicate(usize, usize),
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut s: Vec<char> = text.chars().collect();
    for e in edits {
        let n = s.len().max(1);
        match *e {
            Edit::Delete(at, len) => {
                let a = at % n;
                let b = (a + len % 12).min(s.len());
                s.drain(a.min(s.len())..b);
            }
            Edit::Insert(at, tok) => {
                let a = (at % n).min(s.len());
                let t: Vec<char> = TOKENS[tok % TOKENS.len()].chars().collect();
                s.splice(a..a, t);
            }
            Edit::Truncate(at) => s.truncate(at % n),
            Edit::Duplicate(at, len) => {
                let a = (at % n).min(s.len());
                let b = (a + len % 40).min(s.len());
                let piece: Vec<char> = s[a..b].to_vec();
                s.splice(b..b, piece);
            }
        }
    }
    s.into_iter().collect()
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::Delete(a, b)),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::Insert(a, b)),
        any::<usize>().prop_map(Edit::Truncate),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::Duplicate(a, b)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        run(&String::from_utf8_lossy(&bytes), &library());
    }

    #[test]
    fn random_token_soup_never_panics(toks in proptest::collection::vec(0..TOKENS.len(), 0..80)) {
        let text: String = toks.iter().map(|&t| TOKENS[t]).collect::<Vec<_>>().join(" ");
        run(&text, &library());
    }

    #[test]
    fn mutated_forms_never_panic(which in 0..3usize, edits in proptest::collection::vec(edit(), 1..6)) {
        let text = apply(&sources()[which], &edits);
        run(&text, &library());
    }
}

#[test]
fn every_truncation_of_the_library_is_handled() {
    let loader = library();
    for text in sources() {
        let chars: Vec<(usize, char)> = text.char_indices().collect();
        for &(i, _) in chars.iter().step_by(3) {
            run(&text[..i], &loader);
        }
    }
}

#[test]
fn pathological_inputs_are_refused_cleanly() {
    let loader = library();
    run(&format!("let a = {}1", "-".repeat(5000)), &loader);
    run(&format!("let a = {}", vec!["x"; 3000].join(" + ")), &loader);
    run(&format!("let a = {}1{}", "(".repeat(10000), ")".repeat(10000)), &loader);
    run("form f(u; v) = int(Omega) dot(u, v) * 1e308 * 1e308 / 0", &loader);
    run("fn f(a) = g(a)\nfn g(a) = f(a)\nform k(u; v) = int(Omega) f(1) * dot(u, v)", &loader);
}
