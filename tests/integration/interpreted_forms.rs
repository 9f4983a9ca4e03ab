//! Interpreted forms (`signorini::interpret`) against the compiled kernels of the same files:
//! every form and functional of the library files and of the hybrid test file, residuals,
//! tangents with respect to every field, switches (and whether they decide the tangent) and functional values, on randomly shaped
//! P1 and curved P2 cells in 1D, 2D and 3D at random states, with non-default parameters and
//! function-valued coefs; and one assembly through `Assembler` and `scheme::Bound`.

use std::path::Path;

use signorini::interpret::{InterpretError, InterpretedForm, Library};
use signorini::runtime::fem::assembly::{Assembler, CellIntegral, FacetIntegral, Kernel, Quadrature};
use signorini::runtime::fem::bound::{Bound, BoundForm};
use signorini::runtime::fem::element::ElementKind;
use signorini::runtime::fem::geometry;
use signorini::runtime::fem::kernel::{
    CellCtx, Coef, FacetCtx, FacetTabulation, Form, FormKernel, FunctionalKernel, LocalVector, OnFacet, Tabulation,
    cell_matrix, cell_vector, facet_matrix, facet_vector,
};
use signorini::runtime::fem::mesh::Facet;
use signorini::runtime::fem::mesh::structured::{self, Diagonal};

signorini::forms!("forms/elasticity.wf");
signorini::forms!("forms/neo_hookean.wf");
signorini::forms!("forms/saint_venant_kirchhoff.wf");
signorini::forms!("forms/contact_nitsche.wf");
signorini::forms!("forms/contact_penalty.wf");
signorini::forms!("tests/problems/power_law_penalty.wf");
signorini::forms!("tests/problems/coulomb_penalty.wf");
signorini::forms!("forms/contact_nitsche_coulomb.wf");
signorini::forms!("forms/contact_nitsche_tresca.wf");
signorini::forms!("forms/contact_penalty_coulomb.wf");
signorini::forms!("forms/contact_penalty_deformed.wf");
signorini::forms!("forms/contact_nitsche_traction.wf");
signorini::forms!("tests/problems/transcendental.wf");

const TOL: f64 = 1e-12;
const T: f64 = 0.37;

/// Deterministic pseudo-random numbers in [−1, 1] (xorshift), so failures reproduce.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// Non-default values for every parameter a unit declares.
fn params(names: &[&'static str]) -> Vec<(&'static str, f64)> {
    let value = |n: &str| match n {
        "E" => 2.3,
        "nu" => 0.27,
        "rho" => 1.7,
        "gamma0" => 7.5,
        "theta" => 0.5,
        "F" => 0.8,
        "slip_scale" => 1.3,
        "s" => 0.05,
        "omega" => 1.3,
        _ => panic!("no test value for parameter `{n}`"),
    };
    names.iter().map(|&n| (n, value(n))).collect()
}

/// Case data in dimension d: a body force and a gap that depend on x and t, the obstacle
/// normal −e_d. The gap changes sign along facets that cross x₀ = 0.3, so that some contact
/// quadrature points are active and others not.
struct Data {
    f: Coef,
    g: Coef,
    nc: Coef,
}

impl Data {
    fn new(d: usize) -> Data {
        Data {
            f: Coef::function(d, |x, t, out| {
                for (k, o) in out.iter_mut().enumerate() {
                    *o = (1.3 * x[k] + t).sin() - 0.4 * x[0] * (k as f64 + 1.0);
                }
            }),
            // With its derivatives, for a law that reads it at the displaced point.
            g: Coef::function(1, |x, t, out| out[0] = 0.5 * (x[0] - 0.3) + 0.01 * t).with_derivatives(
                |_, _, order, out| {
                    out.fill(0.0);
                    if order == 1 {
                        out[0] = 0.5;
                    }
                },
            ),
            nc: Coef::constant((0..d).map(|k| if k == d - 1 { -1.0 } else { 0.0 }).collect::<Vec<_>>()),
        }
    }

    /// The coefs a library declares, by name.
    fn list(&self, lib: &Library) -> Vec<(&'static str, Coef)> {
        let all = [("f", &self.f), ("g", &self.g), ("nc", &self.nc)];
        let names = lib.coefs();
        all.into_iter().filter(|(n, _)| names.contains(n)).map(|(n, c)| (n, c.clone())).collect()
    }
}

/// Largest relative difference seen, and how many contact switches were on and off.
#[derive(Default)]
struct Stats {
    worst: f64,
    compared: usize,
    switches: [usize; 2],
}

impl Stats {
    fn close(&mut self, what: &str, compiled: &[f64], interpreted: &[f64]) {
        assert_eq!(compiled.len(), interpreted.len(), "{what}: lengths differ");
        let scale = compiled.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = compiled.iter().zip(interpreted).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let rel = if scale > 0.0 { diff / scale } else { diff };
        assert!(rel <= TOL, "{what}: interpreted differs from compiled by {rel:e} (relative to {scale:e})");
        self.worst = self.worst.max(rel);
        self.compared += 1;
    }
}

fn flat<const D: usize, const N: usize>(v: &LocalVector<D, N>) -> Vec<f64> {
    v.iter().flatten().copied().collect()
}

/// A randomly shaped cell: the reference nodes under a random affine map, every node moved a
/// little more (P2 cells are curved).
fn cell<const D: usize, const N: usize>(kind: ElementKind, rng: &mut Rng) -> [[f64; D]; N] {
    let a: [[f64; D]; D] = std::array::from_fn(|r| std::array::from_fn(|c| f64::from(r == c) + 0.15 * rng.next()));
    let b: [f64; D] = std::array::from_fn(|_| 0.1 * rng.next());
    let nodes = kind.reference_nodes();
    std::array::from_fn(|j| {
        std::array::from_fn(|r| b[r] + (0..D).map(|c| a[r][c] * nodes[j][c]).sum::<f64>() + 0.02 * rng.next())
    })
}

fn state<const D: usize, const N: usize>(rng: &mut Rng) -> LocalVector<D, N> {
    std::array::from_fn(|_| std::array::from_fn(|_| 0.05 * rng.next()))
}

/// Compiled and interpreted kernels of one form on cells of one kind, at a few random states.
fn compare_form_on<const D: usize, const N: usize, K: FormKernel<D, N>>(
    compiled: &K,
    interp: &InterpretedForm,
    kind: ElementKind,
    rng: &mut Rng,
    stats: &mut Stats,
) {
    let meta = compiled.meta();
    let p = kind.degree() as usize - 1;
    for trial in 0..3 {
        let x: [[f64; D]; N] = cell(kind, rng);
        let h = geometry::diameter(&x, D + 1);
        // The fields, then the previous level when the form reads it (`prev`).
        let count = meta.fields.len() + usize::from(meta.previous);
        let states: Vec<LocalVector<D, N>> = (0..count).map(|_| state(rng)).collect();
        let fields: Vec<&LocalVector<D, N>> = states.iter().collect();
        let what = |part: &str| format!("{} on a {} (trial {trial}): {part}", meta.name, kind.name());
        if let Some(deg) = meta.cell_degree {
            let tab = Tabulation::<D, N>::cell(kind, deg[p]).unwrap();
            let (c, i) = (cell_vector(compiled, &tab, &x, &fields, T), cell_vector(interp, &tab, &x, &fields, T));
            stats.close(&what("cell residual"), &flat(&c), &flat(&i));
            for wrt in 0..meta.fields.len() {
                let c = cell_matrix(compiled, &tab, &x, &fields, wrt, T);
                let i = cell_matrix(interp, &tab, &x, &fields, wrt, T);
                stats.close(&what(&format!("cell tangent d/d{}", meta.fields[wrt])), &c.concat(), &i.concat());
                let ctx = CellCtx { tab: &tab, coords: &x, t: T };
                let (mut c, mut i) = (Vec::new(), Vec::new());
                let decided = compiled.cell_switches(&ctx, &fields, wrt, &mut c);
                assert_eq!(decided, interp.cell_switches(&ctx, &fields, wrt, &mut i), "{}", what("cell gates"));
                assert_eq!(c, i, "{}", what("cell switches"));
            }
        }
        for (region, (name, deg)) in meta.facets.iter().enumerate() {
            let tab = FacetTabulation::<D, N>::new(kind, deg[p]).unwrap();
            for facet in 0..tab.facets.len() {
                let at = |part: &str| what(&format!("{part} on {name}, local facet {facet}"));
                let on = OnFacet { region, facet, h };
                let c = facet_vector(compiled, &tab, on, &x, &fields, T);
                let i = facet_vector(interp, &tab, on, &x, &fields, T);
                stats.close(&at("facet residual"), &flat(&c), &flat(&i));
                for wrt in 0..meta.fields.len() {
                    let c = facet_matrix(compiled, &tab, on, &x, &fields, wrt, T);
                    let i = facet_matrix(interp, &tab, on, &x, &fields, wrt, T);
                    stats.close(&at(&format!("facet tangent d/d{}", meta.fields[wrt])), &c.concat(), &i.concat());
                    let (ftab, normal) = &tab.facets[facet];
                    let ctx = FacetCtx { tab: ftab, ref_normal: normal, coords: &x, h, t: T };
                    let (mut c, mut i) = (Vec::new(), Vec::new());
                    let decided = compiled.facet_switches(region, &ctx, &fields, wrt, &mut c);
                    let interpreted = interp.facet_switches(region, &ctx, &fields, wrt, &mut i);
                    assert_eq!(decided, interpreted, "{}", at("facet gates"));
                    assert_eq!(c, i, "{}", at("facet switches"));
                    for s in c {
                        stats.switches[usize::from(s)] += 1;
                    }
                }
            }
        }
    }
}

/// Compiled and interpreted values of one functional on cells of one kind.
fn compare_functional_on<const D: usize, const N: usize, K: FunctionalKernel<D, N>>(
    compiled: &K,
    interp: &InterpretedForm,
    kind: ElementKind,
    rng: &mut Rng,
    stats: &mut Stats,
) {
    let meta = compiled.meta();
    let p = kind.degree() as usize - 1;
    for trial in 0..3 {
        let x: [[f64; D]; N] = cell(kind, rng);
        let h = geometry::diameter(&x, D + 1);
        // The fields, then the previous level when the form reads it (`prev`).
        let count = meta.fields.len() + usize::from(meta.previous);
        let states: Vec<LocalVector<D, N>> = (0..count).map(|_| state(rng)).collect();
        let fields: Vec<&LocalVector<D, N>> = states.iter().collect();
        let what = |part: &str| format!("{} on a {} (trial {trial}): {part}", meta.name, kind.name());
        if let Some(deg) = meta.cell_degree {
            let tab = Tabulation::<D, N>::cell(kind, deg[p]).unwrap();
            let ctx = CellCtx { tab: &tab, coords: &x, t: T };
            stats.close(
                &what("cell value"),
                &[compiled.cell_value(&ctx, &fields)],
                &[interp.cell_value(&ctx, &fields)],
            );
        }
        for (region, (name, deg)) in meta.facets.iter().enumerate() {
            let tab = FacetTabulation::<D, N>::new(kind, deg[p]).unwrap();
            for (facet, (ftab, normal)) in tab.facets.iter().enumerate() {
                let ctx = FacetCtx { tab: ftab, ref_normal: normal, coords: &x, h, t: T };
                let (c, i) = (compiled.facet_value(region, &ctx, &fields), interp.facet_value(region, &ctx, &fields));
                stats.close(&what(&format!("value on {name}, local facet {facet}")), &[c], &[i]);
            }
        }
    }
}

fn same_meta(compiled: &impl Form, interp: &InterpretedForm) {
    assert_eq!(format!("{:?}", compiled.meta()), format!("{:?}", interp.meta()));
}

/// Every element kind of dimension `d`, for a compiled kernel usable on all of them.
fn compare_form<K: Kernel>(compiled: &K, interp: &InterpretedForm, rng: &mut Rng, stats: &mut Stats) {
    same_meta(compiled, interp);
    match interp.dim() {
        1 => compare_form_on::<1, 2, K>(compiled, interp, ElementKind::IntervalP1, rng, stats),
        2 => {
            compare_form_on::<2, 3, K>(compiled, interp, ElementKind::TriangleP1, rng, stats);
            compare_form_on::<2, 6, K>(compiled, interp, ElementKind::TriangleP2, rng, stats);
        }
        _ => {
            compare_form_on::<3, 4, K>(compiled, interp, ElementKind::TetrahedronP1, rng, stats);
            compare_form_on::<3, 10, K>(compiled, interp, ElementKind::TetrahedronP2, rng, stats);
        }
    }
}

fn compare_functional<K: signorini::runtime::fem::assembly::Functional>(
    compiled: &K,
    interp: &InterpretedForm,
    rng: &mut Rng,
    stats: &mut Stats,
) {
    same_meta(compiled, interp);
    match interp.dim() {
        1 => compare_functional_on::<1, 2, K>(compiled, interp, ElementKind::IntervalP1, rng, stats),
        2 => {
            compare_functional_on::<2, 3, K>(compiled, interp, ElementKind::TriangleP1, rng, stats);
            compare_functional_on::<2, 6, K>(compiled, interp, ElementKind::TriangleP2, rng, stats);
        }
        _ => {
            compare_functional_on::<3, 4, K>(compiled, interp, ElementKind::TetrahedronP1, rng, stats);
            compare_functional_on::<3, 10, K>(compiled, interp, ElementKind::TetrahedronP2, rng, stats);
        }
    }
}

/// One test per file: every form (`forms`) and functional (`functionals`) of module `$m`,
/// whose `Coefficients` are built from `Data` by `$coefs`.
macro_rules! unit_test {
    ($test:ident, $m:ident, $path:literal, $coefs:expr, forms: [$($F:ident),*], functionals: [$($G:ident),*]) => {
        #[test]
        fn $test() {
            let lib = Library::load(Path::new($path)).unwrap();
            let names = $m::Params::NAMES;
            let values = params(names);
            let mut p = $m::Params::default();
            for (n, v) in &values {
                p.set(n, *v).unwrap();
            }
            let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
            let mut stats = Stats::default();
            let mut seen = Vec::new();
            for d in 1..=3 {
                let data = Data::new(d);
                let make: fn(&Data) -> $m::Coefficients = $coefs;
                let c = make(&data);
                $(
                    let compiled = $m::$F::new(&p, &c);
                    let name = compiled.meta().name.to_string();
                    let interp = lib.form(&name, d, &values, &data.list(&lib)).unwrap();
                    compare_form(&compiled, &interp, &mut rng, &mut stats);
                    seen.push(name);
                )*
                $(
                    let compiled = $m::$G::new(&p, &c);
                    let name = compiled.meta().name.to_string();
                    let interp = lib.form(&name, d, &values, &data.list(&lib)).unwrap();
                    compare_functional(&compiled, &interp, &mut rng, &mut stats);
                    seen.push(name);
                )*
            }
            seen.sort_unstable();
            seen.dedup();
            let mut all = lib.forms();
            all.sort_unstable();
            assert_eq!(seen, all, "every form and functional of {} is compared", $path);
            let contact = lib.forms().iter().any(|n| n.contains("contact"));
            if contact {
                assert!(stats.switches[0] > 0 && stats.switches[1] > 0, "mixed active sets: {:?}", stats.switches);
            }
            eprintln!(
                "{}: {} comparisons, largest relative difference {:e}, switches off/on {:?}",
                $path, stats.compared, stats.worst, stats.switches
            );
        }
    };
}

unit_test!(
    elasticity_interpreted_matches_compiled,
    elasticity,
    "forms/elasticity.wf",
    |d| elasticity::Coefficients { f: d.f.clone() },
    forms: [Mass, Stiffness, Load, StiffnessDg],
    functionals: [VonMises, Measure]
);

unit_test!(
    neo_hookean_interpreted_matches_compiled,
    neo_hookean,
    "forms/neo_hookean.wf",
    |d| neo_hookean::Coefficients { f: d.f.clone() },
    forms: [Mass, Stiffness, Load],
    functionals: [StrainEnergy, Measure]
);

unit_test!(
    saint_venant_kirchhoff_interpreted_matches_compiled,
    saint_venant_kirchhoff,
    "forms/saint_venant_kirchhoff.wf",
    |d| saint_venant_kirchhoff::Coefficients { f: d.f.clone() },
    forms: [Mass, Stiffness, Load, StiffnessDg],
    functionals: [StrainEnergy, Measure]
);

unit_test!(
    nitsche_interpreted_matches_compiled,
    contact_nitsche,
    "forms/contact_nitsche.wf",
    |d| contact_nitsche::Coefficients { f: d.f.clone(), g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact, HybridContact],
    functionals: [ContactEnergy, ContactWork, ContactJump, ContactPressure, ContactTrial]
);

unit_test!(
    traction_interpreted_matches_compiled,
    contact_nitsche_traction,
    "forms/contact_nitsche_traction.wf",
    |d| contact_nitsche_traction::Coefficients { f: d.f.clone(), g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact, HybridContact],
    functionals: [ContactEnergy, ContactWork, ContactJump, ContactPressure, ContactTrial]
);

unit_test!(
    real_power_interpreted_matches_compiled,
    power_law_penalty,
    "tests/problems/power_law_penalty.wf",
    |d| power_law_penalty::Coefficients { f: d.f.clone(), g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact],
    functionals: [ContactEnergy, ContactPressure, ContactTrial]
);

unit_test!(
    penalty_interpreted_matches_compiled,
    contact_penalty,
    "forms/contact_penalty.wf",
    |d| contact_penalty::Coefficients { f: d.f.clone(), g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact, HybridContact],
    functionals: [ContactEnergy, ContactJump, ContactPressure, ContactTrial]
);

unit_test!(
    coulomb_interpreted_matches_compiled,
    coulomb_penalty,
    "tests/problems/coulomb_penalty.wf",
    |d| coulomb_penalty::Coefficients { f: d.f.clone(), g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact],
    functionals: [ContactEnergy, ContactPressure, FrictionForce, FrictionWork, Slip]
);

unit_test!(
    transcendental_interpreted_matches_compiled,
    transcendental,
    "tests/problems/transcendental.wf",
    |d| transcendental::Coefficients { g: d.g.clone(), nc: d.nc.clone() },
    forms: [Wave, Growth],
    functionals: [Angle, Every]
);

fn bound<'m, K: Kernel + 'm>(kernel: K, contact: &'m [Facet]) -> Box<dyn BoundForm + 'm> {
    Box::new(Bound {
        kernel,
        quadrature: Quadrature::default(),
        regions: vec![("Gamma_C".into(), contact)],
        cells: None,
    })
}

/// Residual, tangent and functionals assembled on a P2 mesh with the contact region on its
/// bottom side, through `scheme::Bound` and `Assembler`.
#[test]
fn assembled_nitsche_contact_matches_compiled() {
    let lib = Library::load(Path::new("forms/contact_nitsche.wf")).unwrap();
    let values = params(contact_nitsche::Params::NAMES);
    let mut p = contact_nitsche::Params::default();
    for (n, v) in &values {
        p.set(n, *v).unwrap();
    }
    let data = Data::new(2);
    let c = contact_nitsche::Coefficients { f: data.f.clone(), g: data.g.clone(), nc: data.nc.clone() };
    let mesh = structured::rectangle(5, 3, [0.0, 1.0], [0.0, 0.6], Diagonal::Right, 2);
    let asm = Assembler::new(&mesh);
    let bottom = asm.region("bottom").unwrap();
    let mut rng = Rng(4242);
    let u: Vec<f64> = (0..asm.size()).map(|_| 0.05 * rng.next()).collect();
    let interp = |name: &str| lib.form(name, 2, &values, &data.list(&lib)).unwrap();
    let elib = Library::load(Path::new("forms/elasticity.wf")).unwrap();
    let evalues = params(elasticity::Params::NAMES);
    let mut ep = elasticity::Params::default();
    for (n, v) in &evalues {
        ep.set(n, *v).unwrap();
    }
    let ecoefs = elasticity::Coefficients { f: data.f.clone() };
    let interp_e = |name: &str| elib.form(name, 2, &evalues, &data.list(&elib)).unwrap();
    let pairs = [
        (bound(contact_nitsche::Contact::new(&p, &c), bottom), bound(interp("contact"), bottom)),
        (bound(elasticity::Stiffness::new(&ep, &ecoefs), bottom), bound(interp_e("stiffness"), bottom)),
    ];
    let mut stats = Stats::default();
    for (compiled, interpreted) in &pairs {
        let name = compiled.name().to_string();
        assert_eq!(name, interpreted.name());
        assert_eq!(
            (compiled.linear(), compiled.piecewise(), compiled.fields()),
            (interpreted.linear(), interpreted.piecewise(), interpreted.fields())
        );
        let (mut rc, mut ri) = (vec![0.0; asm.size()], vec![0.0; asm.size()]);
        compiled.residual(&asm, &[&u], T, &mut rc);
        interpreted.residual(&asm, &[&u], T, &mut ri);
        stats.close(&format!("assembled {name} residual"), &rc, &ri);
        let (mut mc, mut mi) = (asm.zero_matrix(), asm.zero_matrix());
        compiled.tangent(&asm, &[&u], 0, T, &mut mc);
        interpreted.tangent(&asm, &[&u], 0, T, &mut mi);
        stats.close(&format!("assembled {name} tangent"), &mc.values, &mi.values);
        let (mut sc, mut si) = (Vec::new(), Vec::new());
        compiled.switches(&asm, &[&u], 0, T, &mut sc);
        interpreted.switches(&asm, &[&u], 0, T, &mut si);
        assert_eq!(sc, si, "assembled {name} switches");
        for s in sc {
            stats.switches[usize::from(s)] += 1;
        }
    }
    assert!(stats.switches[0] > 0 && stats.switches[1] > 0, "mixed active set: {:?}", stats.switches);
    let q = Quadrature::default();
    let energy = (contact_nitsche::ContactEnergy::new(&p, &c), interp("contact_energy"));
    let (ec, ei) = (
        asm.facet_value(
            FacetIntegral { kernel: &energy.0, region: "Gamma_C", facets: bottom, quadrature: q, cells: None },
            &[&u],
            T,
        ),
        asm.facet_value(
            FacetIntegral { kernel: &energy.1, region: "Gamma_C", facets: bottom, quadrature: q, cells: None },
            &[&u],
            T,
        ),
    );
    stats.close("assembled contact energy", &[ec], &[ei]);
    let vm = (elasticity::VonMises::new(&ep, &ecoefs), interp_e("von_mises"));
    stats.close(
        "assembled von Mises",
        &[asm.cell_value(CellIntegral::all(&vm.0, q), &[&u], T)],
        &[asm.cell_value(CellIntegral::all(&vm.1, q), &[&u], T)],
    );
    eprintln!("assembled: largest relative difference {:e}", stats.worst);
}

#[test]
fn errors_name_the_problem() {
    let lib = Library::load(Path::new("forms/contact_nitsche.wf")).unwrap();
    let data = Data::new(2);
    let coefs = data.list(&lib);
    let err = |r: Result<InterpretedForm, InterpretError>| r.expect_err("an error").to_string();
    let e = err(lib.form("contakt", 2, &[], &coefs));
    assert!(
        e.contains("`contakt`")
            && e.contains(
                "contact, contact_energy, contact_work, contact_jump, contact_pressure, contact_trial, hybrid_contact"
            ),
        "{e}"
    );
    let e = err(lib.form("contact", 2, &[("gamma", 1.0)], &coefs));
    assert!(e.contains("unknown parameter `gamma`") && e.contains("gamma0"), "{e}");
    let e = err(lib.form("contact", 2, &[("theta", 2.0)], &coefs));
    assert!(e.contains("[-1, 1]") && e.contains("contact_nitsche.wf:9"), "{e}");
    let e = err(lib.form("contact", 2, &[("nu", 0.5)], &coefs));
    assert!(e.contains("[0, 0.5)") && e.contains("elasticity.wf:5"), "{e}");
    let e = err(lib.form("contact", 2, &[("E", f64::NAN)], &coefs));
    assert!(e.contains("(0, inf)"), "{e}");
    let e = err(lib.form("contact", 2, &[], &coefs[..2]));
    assert!(e.contains("missing coef `nc`") && e.contains("contact_nitsche.wf:"), "{e}");
    let e = err(lib.form("contact", 3, &[], &coefs));
    assert!(e.contains("`f`") && e.contains("needs 3"), "{e}");
    let e = err(lib.form("contact", 4, &[], &coefs));
    assert!(e.contains("not 4"), "{e}");
    let e = Library::load(Path::new("tests/wf/no_such_file.wf")).expect_err("an error").to_string();
    assert!(e.contains("no_such_file"), "{e}");

    let dir = std::env::temp_dir().join(format!("signorini-interp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.wf");
    std::fs::write(&bad, "param a = 1\nform f(u; v) = int(Omega) dot(u, w)\n").unwrap();
    let e = Library::load(&bad).expect_err("an error").to_string();
    assert!(e.contains("bad.wf:2"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
    let mut f = lib.form("contact", 2, &[], &coefs).unwrap();
    assert_eq!(f.param("gamma0"), Some(5.0));
    f.set_param("gamma0", 9.0).unwrap();
    assert_eq!(f.param("gamma0"), Some(9.0));
    assert!(f.set_param("gamma0", -1.0).is_err());
    assert_eq!(f.param("gamma0"), Some(9.0));
}

unit_test!(
    nitsche_coulomb_interpreted_matches_compiled,
    contact_nitsche_coulomb,
    "forms/contact_nitsche_coulomb.wf",
    |d| contact_nitsche_coulomb::Coefficients { f: d.f.clone(), g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact, HybridContact],
    functionals: [ContactEnergy, ContactWork, FrictionWork, FrictionForce, ContactJump, ContactPressure, ContactTrial]
);

unit_test!(
    nitsche_tresca_interpreted_matches_compiled,
    contact_nitsche_tresca,
    "forms/contact_nitsche_tresca.wf",
    |d| contact_nitsche_tresca::Coefficients { f: d.f.clone(), g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact, HybridContact],
    functionals: [ContactEnergy, ContactWork, FrictionWork, FrictionForce, ContactJump, ContactPressure, ContactTrial]
);

unit_test!(
    penalty_coulomb_interpreted_matches_compiled,
    contact_penalty_coulomb,
    "forms/contact_penalty_coulomb.wf",
    |d| contact_penalty_coulomb::Coefficients { f: d.f.clone(), g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact, HybridContact],
    functionals: [ContactEnergy, FrictionWork, FrictionForce, ContactJump, ContactPressure, ContactTrial]
);

unit_test!(
    penalty_deformed_interpreted_matches_compiled,
    contact_penalty_deformed,
    "forms/contact_penalty_deformed.wf",
    |d| contact_penalty_deformed::Coefficients { g: d.g.clone(), nc: d.nc.clone() },
    forms: [Contact, HybridContact],
    functionals: [ContactEnergy, FrictionWork, FrictionForce, ContactJump, ContactPressure, ContactTrial]
);
