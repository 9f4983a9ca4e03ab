//! (f) The frictional laws' tangents in each regime: every library law that provides
//! `friction_work` (found in the library, not named here), at its file's defaults, on a small
//! P2 block pressed onto the plane y = 0: its `contact` tangent against central differences of
//! its residual in separation, stick and slip, each regime shown to be the one intended by what
//! the law's own functionals report:
//! - separation: `contact_pressure` is zero;
//! - slip: `friction_force` is saturated (the same for a slip half as large again);
//! - stick: `friction_force` is below 90 % of the saturated value at the same normal state.
//!
//! With each, whether the active set decides the tangent there (`BoundForm::switches`): a
//! Coulomb law's does where its friction radius is zero.

use serde::Serialize;

use crate::error::CaseError;
use crate::runtime::fem::assembly::Assembler;
use crate::runtime::fem::bound::{BoundForm, with_previous};
use crate::runtime::fem::kernel::Coef;
use crate::runtime::fem::mesh::Mesh;
use crate::runtime::fem::mesh::structured::{Diagonal, rectangle};
use crate::runtime::library::Binding;

/// Largest difference between the tangent and central differences, relative to the tangent's
/// largest entry (or absolute below 1): the differences' own error is ~ε/δ + δ² ≈ 1e-8.
pub const TOLERANCE: f64 = 1e-6;

/// The regimes, with the block's lift (negative: pressed in) and the slip since the previous
/// level along x.
const REGIMES: [(&str, f64, f64); 3] = [("separation", 0.05, 0.3), ("stick", -0.01, 1e-6), ("slip", -0.01, 0.3)];

/// One law in one regime.
#[derive(Clone, Debug, Serialize)]
pub struct RegimeRow {
    pub contact: String,
    pub regime: String,
    /// The tangent against central differences (see [`TOLERANCE`]).
    pub error: f64,
    /// ∫ |λ_N| (`contact_pressure`), ∫ |t| (`friction_force`) and its saturated value.
    pub pressure: f64,
    pub friction: f64,
    pub saturated: f64,
    /// The state is in the regime intended.
    pub present: bool,
    /// The active set decides the tangent at this state.
    pub decided: bool,
}

impl RegimeRow {
    pub fn passed(&self) -> bool {
        self.present && self.error <= TOLERANCE
    }
}

/// A P2 block [0, 1] × [0, 0.5] whose bottom is `Gamma_C`.
fn block() -> Mesh {
    let mut mesh = rectangle(2, 1, [0.0, 1.0], [0.0, 0.5], Diagonal::Right, 2);
    mesh.add_region_where("Gamma_C", |_, x| x[1].abs() < 1e-12);
    mesh
}

/// A pseudo-random number in [−1, 1) (xorshift): states away from the laws' kinks.
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        2.0 * ((self.0 >> 11) as f64 / (1u64 << 53) as f64) - 1.0
    }
}

/// Every frictional law of the library in every regime.
pub fn regimes(progress: &mut dyn FnMut(&str)) -> Result<Vec<RegimeRow>, CaseError> {
    let mesh = block();
    let region = mesh.region("Gamma_C").map_err(|e| CaseError::Option(e.to_string()))?;
    let binding = Binding::new(Default::default(), vec![("Gamma_C".to_string(), region.facets.as_slice())], 2);
    let coefs = |name: &str| match name {
        // With its derivatives, for a law that reads it at the displaced point.
        "g" => Some(Coef::function(1, |x, _, out| out[0] = x[1]).with_derivatives(|_, _, order, out| {
            out.fill(0.0);
            if order == 1 {
                out[1] = 1.0;
            }
        })),
        "nc" => Some(Coef::constant(vec![0.0, -1.0])),
        "f" => Some(Coef::constant(vec![0.0, 0.0])),
        _ => None,
    };
    let asm = Assembler::new(&mesh);
    let mut rows = Vec::new();
    for law in crate::driver::frictional_contact_names() {
        progress(&format!("regime tangents: {law}"));
        let methods = crate::driver::Methods { contact: law.to_string(), ..Default::default() };
        let forms = crate::driver::FilesInUse::resolve_forms(&methods, &[])?;
        let mut instance = forms.instantiate(&coefs, &binding)?;
        let missing = |slot: &str| CaseError::Option(format!("contact law `{law}` provides no `{slot}`"));
        let contact = instance.take_form("contact").ok_or_else(|| missing("contact"))?;
        let pressure = instance.take_functional("contact_pressure").ok_or_else(|| missing("contact_pressure"))?;
        let friction = instance.take_functional("friction_force").ok_or_else(|| missing("friction_force"))?;
        let mut noise = Noise(0x2545_f491_4f6c_dd1d);
        for (regime, lift, slide) in REGIMES {
            let (u, previous) = state(&mesh, &mut noise, lift, slide);
            let force = |w: &[f64]| friction.value(&asm, &[&u, w], 0.0).abs();
            // The same normal state slid far: saturated, if a half larger slide changes nothing.
            let far = |s: f64| shifted(&u, s);
            let (saturated, further) = (force(&far(0.3)), force(&far(0.45)));
            let saturates = (saturated - further).abs() <= 1e-9 * saturated.max(f64::MIN_POSITIVE);
            let p = pressure.value(&asm, &[&u], 0.0).abs();
            let t = force(&previous);
            let present = match regime {
                "separation" => p == 0.0,
                "stick" => p > 0.0 && saturates && t < 0.9 * saturated,
                _ => p > 0.0 && (t - force(&shifted(&u, 1.5 * slide))).abs() <= 1e-9 * t,
            };
            let mut set = Vec::new();
            let decided =
                contact.switches(&asm, &with_previous(contact.previous(), &[&u], &previous), 0, 0.0, &mut set);
            rows.push(RegimeRow {
                contact: law.to_string(),
                regime: regime.to_string(),
                error: fd_error(&asm, contact.as_ref(), &u, &previous),
                pressure: p,
                friction: t,
                saturated,
                present,
                decided,
            });
        }
    }
    Ok(rows)
}

/// (u, previous): the block lifted by `lift` (tilted a little, with noise), the previous level
/// `slide` further along x (±10 %).
fn state(mesh: &Mesh, noise: &mut Noise, lift: f64, slide: f64) -> (Vec<f64>, Vec<f64>) {
    let n = mesh.num_nodes();
    let mut u = vec![0.0; 2 * n];
    let mut previous = vec![0.0; 2 * n];
    for i in 0..n {
        let x = mesh.node(i)[0];
        u[2 * i] = 0.001 * noise.next();
        u[2 * i + 1] = lift - 0.002 * x + 0.0005 * noise.next();
        previous[2 * i] = u[2 * i] - slide * (1.0 + 0.1 * noise.next());
        previous[2 * i + 1] = u[2 * i + 1];
    }
    (u, previous)
}

/// `u` slid back by `s` along x: a previous level `s` behind.
fn shifted(u: &[f64], s: f64) -> Vec<f64> {
    u.iter().enumerate().map(|(k, v)| if k % 2 == 0 { v - s } else { *v }).collect()
}

/// Max-norm difference between the tangent in u (the previous level held) and central
/// differences of the residual, relative to the tangent's largest entry or absolute below 1.
fn fd_error(asm: &Assembler, form: &dyn BoundForm, u: &[f64], previous: &[f64]) -> f64 {
    let n = u.len();
    let residual = |v: &[f64]| {
        let mut r = vec![0.0; n];
        form.residual(asm, &with_previous(form.previous(), &[v], previous), 0.0, &mut r);
        r
    };
    let mut j = asm.zero_matrix();
    form.tangent(asm, &with_previous(form.previous(), &[u], previous), 0, 0.0, &mut j);
    let mut columns = Vec::with_capacity(n);
    let mut unit = vec![0.0; n];
    for c in 0..n {
        unit[c] = 1.0;
        let mut col = vec![0.0; n];
        j.mul_vec(&unit, &mut col);
        unit[c] = 0.0;
        columns.push(col);
    }
    let scale = columns.iter().flatten().fold(1.0f64, |m, v| m.max(v.abs()));
    let eps = 1e-8;
    let mut worst = 0.0f64;
    for (c, col) in columns.iter().enumerate() {
        let (mut up, mut down) = (u.to_vec(), u.to_vec());
        up[c] += eps;
        down[c] -= eps;
        let (rp, rm) = (residual(&up), residual(&down));
        for row in 0..n {
            let fd = (rp[row] - rm[row]) / (2.0 * eps);
            worst = worst.max((fd - col[row]).abs() / scale);
        }
    }
    worst
}

/// The table, as Markdown.
pub fn markdown(rows: &[RegimeRow]) -> String {
    let mut md = format!(
        "### (f) Frictional tangents in each regime\n\nEvery library law that provides `friction_work`, at its file's defaults, on a P2 block [0, 1] × [0, 0.5] pressed onto the plane y = 0 (or lifted off it): its `contact` tangent against central differences of its residual (δ = 1e-8; relative to the tangent's largest entry; tolerance {TOLERANCE:.0e}). Each state is checked to be in its regime by the law's own functionals: no `contact_pressure` in separation; `friction_force` saturated in slip (unchanged when the slip grows by half), below 90 % of its saturated value at the same normal state in stick. The last column says whether the active set decides the tangent there (a Coulomb law's does where its friction radius is zero: Newton then reuses factorizations as for a frictionless law).\n\n| contact | regime | tangent error | ∫ λ_N | ∫ t | saturated | regime present | set decides tangent |\n|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        let yes = |b: bool| if b { "yes" } else { "no" };
        let present = if r.present { "yes" } else { "**no**" };
        let error = if r.error <= TOLERANCE { format!("{:.1e}", r.error) } else { format!("**{:.1e}**", r.error) };
        md.push_str(&format!(
            "| {} | {} | {error} | {:.3e} | {:.3e} | {:.3e} | {present} | {} |\n",
            r.contact,
            r.regime,
            r.pressure,
            r.friction,
            r.saturated,
            yes(r.decided)
        ));
    }
    md
}
