//! The Rust the compiler generates for every file of the form library (`forms/`,
//! `forms/schemes/`), as `signorini emit --stage rust` prints it and the snapshots record it,
//! compiled here with every warning an error: generated code that warns (rustc's lints, or
//! clippy's under `cargo clippy`) fails the build of this crate, and so `cargo test`.

#![deny(warnings)]

include!(concat!(env!("OUT_DIR"), "/generated.rs"));

/// Test files outside the library (`tests/problems/transcendental.wf`: every transcendental
/// built-in), compiled here too, and not among the library's units.
pub mod fixtures {
    include!(concat!(env!("OUT_DIR"), "/fixtures.rs"));
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use signorini_compiler::scheme::{eval_all, layout};
    use signorini_compiler::{FsLoader, compile, describe};

    fn library() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../forms")
    }

    /// The stems of the `.wf` files of a folder.
    fn stems(dir: &Path) -> Vec<String> {
        let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        entries
            .map(|e| e.expect("a readable entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "wf"))
            .map(|p| p.file_stem().expect("a file name").to_string_lossy().into_owned())
            .collect()
    }

    #[test]
    fn every_file_of_the_library_is_compiled_here() {
        let mut expected = stems(&library());
        expected.extend(stems(&library().join("schemes")));
        expected.sort();
        let mut compiled: Vec<&str> = super::UNITS.iter().map(|u| u.name).collect();
        compiled.sort();
        assert_eq!(compiled, expected);
    }

    /// The params, coefs and slots the generated code describes are those the compiler
    /// describes to a file interpreted at run time (ranges to the bit: Rust evaluates the
    /// bounds as written as the checker does).
    #[test]
    fn generated_descriptions_are_the_compilers() {
        for unit in super::UNITS {
            let dir = if unit.schemes.is_empty() { library() } else { library().join("schemes") };
            let path = dir.join(unit.file);
            let compiled = compile(&path, &FsLoader).unwrap_or_else(|e| panic!("{}:\n{e}", path.display()));
            let prog = &compiled.program;
            if let Some(forms) = unit.forms {
                assert_eq!(describe::params(prog), forms.params, "{}", unit.name);
                assert_eq!(describe::coefs(prog), forms.coefs, "{}", unit.name);
                assert_eq!(describe::slots(prog), forms.slots, "{}", unit.name);
            }
            for s in unit.schemes {
                let ir = prog.schemes.iter().find(|i| i.name == s.name).expect("the scheme compiles");
                assert_eq!(describe::scheme_params(prog, ir), s.params, "{}", s.name);
            }
        }
    }

    /// A scheme's generated `coefficients` computes what the IR evaluator computes from the
    /// compiled scheme, bit for bit: the emitter writes each node as one operation, in the
    /// graph's order, whether it binds it to a `let` or inlines it.
    #[test]
    fn generated_scheme_coefficients_are_the_ir_evaluators_to_the_bit() {
        let mut checked = 0;
        for unit in super::UNITS {
            for s in unit.schemes {
                let path = library().join("schemes").join(unit.file);
                let compiled = compile(&path, &FsLoader).unwrap_or_else(|e| panic!("{}:\n{e}", path.display()));
                let ir = compiled.schemes().iter().find(|i| i.name == s.name).expect("the scheme compiles");
                let layout = layout::layout(ir, &compiled.program.sources);
                assert_eq!(&layout.desc, s.desc, "{}: the generated description is the layout's", s.name);
                let order = layout.coefficients;
                let defaults: Vec<f64> = s.params.iter().map(|p| p.default).collect();
                let scheme = (s.make)(&defaults).expect("the defaults are in range");
                for (dt, t) in [(1e-3, 0.0), (0.05, 0.7), (2.0, 3.0)] {
                    let mut generated = vec![f64::NAN; s.desc.coefficients];
                    scheme.coefficients(dt, t, &mut generated);
                    let evaluated = eval_all(&ir.graph, &order, &defaults, dt, t);
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(&generated), bits(&evaluated), "{} at dt = {dt}, t = {t}", s.name);
                }
                checked += 1;
            }
        }
        assert!(checked >= 9, "{checked} schemes");
    }

    /// The fixture's functional `every`, which applies each transcendental built-in to the
    /// field, has the same bits in the generated kernel as in the IR evaluator (the
    /// interpreter), on a P1 and a curved P2 triangle: the emitter writes each function as the
    /// `f64` method the evaluator calls, and a functional has no sum over basis functions whose
    /// order could differ.
    #[test]
    fn generated_transcendental_functions_are_the_ir_evaluators_to_the_bit() {
        use signorini::interpret::Library;
        use signorini::runtime::fem::element::ElementKind;
        use signorini::runtime::fem::kernel::{CellCtx, Coef, Form, FunctionalKernel, LocalVector, Tabulation};

        use crate::fixtures::transcendental as fixture;

        let path = library().join("../tests/problems/transcendental.wf");
        let lib = Library::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let (g, nc) = (Coef::constant(vec![0.1]), Coef::constant(vec![0.6, -0.8]));
        let coefs = fixture::Coefficients { g: g.clone(), nc: nc.clone() };
        let compiled = fixture::Every::new(&fixture::Params::default(), &coefs);
        let interpreted = lib.form("every", 2, &[], &[("g", g), ("nc", nc)]).expect("the functional binds");
        let degree = compiled.meta().cell_degree.expect("a cell integral");
        fn compare<const N: usize>(
            compiled: &impl FunctionalKernel<2, N>,
            interpreted: &impl FunctionalKernel<2, N>,
            kind: ElementKind,
            degree: u32,
        ) -> usize {
            let tab = Tabulation::<2, N>::cell(kind, degree).expect("a rule of this degree");
            let nodes = kind.reference_nodes();
            // The reference cell stretched and sheared, its nodes moved a little (curved P2).
            let x: [[f64; 2]; N] = std::array::from_fn(|j| {
                let (r, s) = (nodes[j][0], nodes[j][1]);
                [1.2 * r + 0.3 * s + 0.01 * (j as f64).sin(), 0.9 * s - 0.1 * r + 0.01 * (j as f64).cos()]
            });
            let mut compared = 0;
            for k in 0..8 {
                let u: LocalVector<2, N> =
                    std::array::from_fn(|j| [0.3 * ((k * N + j) as f64).sin(), 0.3 * ((k + 2 * j) as f64).cos()]);
                let ctx = CellCtx { tab: &tab, coords: &x, t: 0.3 };
                let (a, b) = (compiled.cell_value(&ctx, &[&u]), interpreted.cell_value(&ctx, &[&u]));
                assert!(a.is_finite(), "{} state {k}: {a}", kind.name());
                assert_eq!(a.to_bits(), b.to_bits(), "{} state {k}: generated {a}, evaluated {b}", kind.name());
                compared += 1;
            }
            compared
        }
        let p1 = compare::<3>(&compiled, &interpreted, ElementKind::TriangleP1, degree[0]);
        let p2 = compare::<6>(&compiled, &interpreted, ElementKind::TriangleP2, degree[1]);
        assert_eq!(p1 + p2, 16);
    }
}
