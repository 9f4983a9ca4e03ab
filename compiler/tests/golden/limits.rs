//! Compiler limits on generated, oversized inputs: each is refused with a located diagnostic
//! (or compiles), through code generation, on the default test-thread stack.

use std::path::Path;

use signorini_compiler::{MemLoader, codegen, compile_text};

/// Compiles `text` as `forms/limits.wf` through code generation; the rendered diagnostics, or
/// `None` if it compiled.
fn run(text: &str) -> Option<String> {
    let loader =
        MemLoader::default().with("forms/elasticity.wf", std::fs::read_to_string("../forms/elasticity.wf").unwrap());
    match compile_text(Path::new("forms/limits.wf"), text, &loader) {
        Err(f) => Some(f.rendered),
        Ok(c) => {
            let opts =
                codegen::Options { runtime: "::rt".into(), module: "limits".into(), source_name: "limits.wf".into() };
            c.rust(&opts).expect("valid input generates code");
            None
        }
    }
}

fn refused(text: &str, code: &str) -> String {
    let r = run(text).unwrap_or_else(|| panic!("compiled; expected {code}"));
    assert!(r.contains(&format!("error[{code}]")), "expected {code}, got:\n{}", &r[..r.len().min(3000)]);
    assert!(r.contains("forms/limits.wf:"), "not located:\n{r}");
    r
}

#[test]
fn a_long_let_chain_is_refused_at_its_depth_limit() {
    let mut text = String::from("let a0 = 1\n");
    for i in 1..100_000 {
        text.push_str(&format!("let a{i} = a{} + 1\n", i - 1));
    }
    text.push_str("form f(u; v) = int(Omega) a99999 * dot(u, v)\n");
    refused(&text, "E0002");
}

#[test]
fn a_long_let_chain_written_backwards_is_refused() {
    let mut text = String::from("form f(u; v) = int(Omega) a0 * dot(u, v)\n");
    for i in 0..100_000 {
        text.push_str(&format!("let a{i} = a{} + 1\n", i + 1));
    }
    text.push_str("let a100000 = 1\n");
    refused(&text, "E0002");
}

#[test]
fn deeply_nested_parentheses_are_refused() {
    let n = 100_000;
    let text = format!("form f(u; v) = int(Omega) {}1{} * dot(u, v)\n", "(".repeat(n), ")".repeat(n));
    refused(&text, "E0002");
}

#[test]
fn a_let_chain_below_the_limit_compiles() {
    let mut text = String::from("let a0 = 1\n");
    for i in 1..200 {
        text.push_str(&format!("let a{i} = a{} * (1 + x[0]) + 1\n", i - 1));
    }
    text.push_str("form f(u; v) = int(Omega) a199 * dot(u, v)\n");
    let _ = run(&text);
}

#[test]
fn nested_functions_expand_in_linear_time() {
    let mut text = String::from("fn f0(y) = y*y\n");
    for i in 1..30 {
        text.push_str(&format!("fn f{i}(y) = f{}(y)*f{}(y)\n", i - 1, i - 1));
    }
    text.push_str("form f(u; v) = int(Omega) f29(dot(u, u)) * dot(u, v)\n");
    let _ = run(&text);
}

#[test]
fn functions_whose_expansion_grows_exponentially_are_refused() {
    let mut text = String::from("fn f0(y) = y*y\n");
    for i in 1..30 {
        text.push_str(&format!("fn f{i}(y) = f{}(y + 1)*f{}(2*y)\n", i - 1, i - 1));
    }
    text.push_str("form f(u; v) = int(Omega) f29(dot(u, u)) * dot(u, v)\n");
    refused(&text, "E0002");
}

#[test]
fn constant_arithmetic_must_be_finite() {
    for (e, at) in [("1/0", "1/0"), ("0/0", "0/0"), ("0^-1", "0^-1"), ("1e308*10", "1e308*10")] {
        let r = refused(&format!("form f(u; v) = int(Omega) {e} * dot(u, v)\n"), "E0004");
        assert!(r.contains(at), "{r}");
    }
    refused("form f(u; v) = int(Omega) dot(u, v) / (dot(u, u) - dot(u, u))\n", "E0004");
}

#[test]
fn stage_times_must_be_finite() {
    let text = "scheme s(alpha = 0.5 in [0, 1]) {\n  uses mass\n  state u\n  stage one at t + dt/alpha {\n    unknown u'\n    residual mass(u') == mass(u)\n  }\n}\n";
    refused(text, "E0818");
    refused(&text.replace("dt/alpha", "dt/0"), "E0004");
}

#[test]
fn high_quadrature_degrees_are_refused() {
    refused("form f(u; v) = int(Omega) dot(u, u)^20 * dot(u, v)\n", "E0503");
    // The help names the way out, and a degree the file sets is the author's.
    let text = refused("form f(u; v) = int(Omega) dot(u, u)^20 * dot(u, v)\n", "E0503");
    assert!(text.contains("int(Omega, degree = 20)"), "{text}");
    let path = Path::new("forms/limits.wf");
    let set = "form f(u; v) = int(Omega, degree = 6) dot(u, u)^20 * dot(u, v)\n";
    let rust = signorini_compiler::compile_to_rust(path, &MemLoader::default().with(path, set), "::rt");
    assert!(rust.is_ok(), "a set degree compiles");
}

#[test]
fn a_quadrature_degree_is_an_integer_in_range() {
    for k in ["2.5", "21", "1e9"] {
        refused(&format!("form f(u; v) = int(Omega, degree = {k}) dot(u, v)\n"), "E0504");
    }
}

/// `int(REGION, degree = K)` replaces the estimate in the generated kernel's metadata, for
/// every element degree.
#[test]
fn a_set_quadrature_degree_reaches_the_kernel() {
    let path = Path::new("forms/limits.wf");
    let text = "form f(u; v) = int(Omega, degree = 3) dot(u, u)^4 * dot(u, v)\n";
    let compiled = signorini_compiler::compile(path, &MemLoader::default().with(path, text)).expect("compiles");
    for ir in compiled.irs() {
        let i = &ir.forms[0].integrals[0];
        assert_eq!(i.degree, [3, 3]);
        assert_eq!(i.estimated, [10, 20]);
    }
}

#[test]
fn diagnostics_are_capped_per_file() {
    let text = "let a = )\n".repeat(20_000);
    let r = run(&text).unwrap();
    assert!(r.len() < 100_000, "{} bytes", r.len());
    assert!(r.contains("more diagnostics in forms/limits.wf not shown"), "{}", &r[r.len() - 500..]);
}

#[test]
fn a_file_name_that_is_not_an_identifier_names_a_valid_module() {
    let path = Path::new("forms/9 bad-name.wf");
    let loader = MemLoader::default().with(path, "form m(a; v) = int(Omega) dot(a, v)\n");
    let rust = signorini_compiler::compile_to_rust(path, &loader, "::rt").expect("compiles");
    assert!(rust.contains("pub mod _9_bad_name {"), "{}", &rust[..400]);
    assert!(rust.contains("name: \"9 bad-name\""), "the unit keeps the file's own name");
}
