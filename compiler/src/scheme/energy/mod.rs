//! A scheme's discrete energy identity (`emit --stage energy`, issue 55), built on exact
//! algebra: the scheme's scalars as rational functions of its params, dt and t ([`exact`]),
//! over polynomials kept expanded ([`poly`]) so that a coefficient is zero exactly when it is
//! the zero polynomial ([`ratfn`]); its step with every level and residual argument an exact
//! combination of the step's free variables ([`window`]); the derivation by multipliers
//! ([`engine`], over the quadratic forms of [`forms`]); the dissipation as a sum of squares
//! and what it proves, at a point and over the params' ranges ([`classify`], with [`factor`]
//! and the certified signs of [`sign`]); the printing in the scheme's names ([`names`],
//! [`print`]) and the `claim energy` check ([`claim`]). Derived exactly for every library
//! scheme: Newmark's at symbolic β, γ (Krenk's kept energy and dissipation), central
//! differences' (E − dt²/8‖a‖²_M kept), the midpoint family's (D ≡ 0), TR-BDF2's (E kept, for
//! every gs), HHT-α's (with ½α(½ − α)‖u − u⁻‖²_K) and generalized-α's (over two steps, its
//! levels weighted by α_m).

pub mod claim;
pub mod classify;
pub mod engine;
pub mod evaluate;
pub mod exact;
pub mod factor;
pub mod forms;
pub mod names;
pub mod poly;
pub mod poly_factors;
pub mod print;
pub mod ratfn;
pub mod sign;
pub mod window;

/// Why `ir` has no energy identity, in its own terms.
pub fn why(ir: &crate::scheme::ir::SchemeIr, e: &engine::NoIdentity) -> String {
    use engine::NoIdentity::*;
    match e {
        NoState(what) => format!("the scheme has no {what} state: the energy ½v·M·v + ½u·K·u needs one"),
        Inconsistent => "no quadratic energy of the states is kept or dissipated by its step: the conditions on \
             the residuals' multipliers contradict each other (the energies tried: E, E + q·½dt²‖a‖²_M, and with \
             q·½‖u - u⁻‖²_K of the previous step)"
            .into(),
        NotUnique => "the conditions leave a family of identities, and none is chosen silently".into(),
        NotRational(r) => format!(
            "the coefficient `{}` is no rational function of the params ({})",
            crate::scheme::print::scalar(&ir.graph, r.node),
            r.why
        ),
        ReadsTime => "a coefficient of its step depends on the time t: the identity needs the step's coefficients \
                      the same from step to step (a load may be applied at any time)"
            .into(),
        Overflow => "its exact coefficients overflow 128-bit rationals".into(),
    }
}

/// Every library scheme (`forms/schemes/`), compiled, by file stem.
#[cfg(test)]
fn library_schemes() -> Vec<(String, crate::scheme::ir::SchemeIr)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../forms/schemes");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("forms/schemes")
        .filter_map(|e| e.ok()?.path().file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    assert!(names.len() >= 9, "{names:?}");
    names
        .into_iter()
        .map(|name| {
            let (prog, _) = crate::check_path(&dir.join(format!("{name}.wf")), &crate::source::FsLoader)
                .unwrap_or_else(|f| panic!("{}", f.rendered));
            (name, prog.schemes.into_iter().next().expect("a scheme"))
        })
        .collect()
}
