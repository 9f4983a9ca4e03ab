//! The oscillator ü + u = 0 as a one-dof finite-element system, stepped by any scheme: its
//! error against cos t, and the spectral radius of a scheme's one-step map.

use crate::driver::{FilesInUse, Methods, Slot};
use crate::error::CaseError;
use crate::runtime::fem::assembly::{Assembler, Quadrature};
use crate::runtime::fem::bound::MatrixForm;
use crate::runtime::fem::kernel::Coef;
use crate::runtime::fem::mesh::structured;
use crate::runtime::library::Binding;
use crate::runtime::linalg::Structure;
use crate::runtime::nonlinear::newton::NewtonOptions;
use crate::runtime::nonlinear::statics::Constraints;
use crate::runtime::time::scheme::TimeScheme;
use crate::runtime::time::stepper::Stepper;

/// Runs `f` with a stepper of `methods`'s scheme on the oscillator: one P1 element, E = 1,
/// ρ = 3, so M = ρh/3 = 1 and K = E/h = 1 on the free dof; no contact facets.
pub fn with_oscillator<R>(methods: &Methods, f: impl FnOnce(&mut Stepper) -> R) -> Result<R, CaseError> {
    with_oscillator_scheme(methods, None, f)
}

/// As [`with_oscillator`], stepping `scheme` (e.g. one compiled by a crate's own `forms!`)
/// instead of `methods`'s when given; the forms still come from `methods`.
pub fn with_oscillator_scheme<R>(
    methods: &Methods,
    scheme: Option<Box<dyn TimeScheme>>,
    f: impl FnOnce(&mut Stepper) -> R,
) -> Result<R, CaseError> {
    oscillator(methods, scheme, None, f)
}

/// As [`with_oscillator`] on ü + 2ζu̇ + u = 0: the damping slot (forms/library.toml) is bound
/// to 2ζM. (Without this, a scheme that applies it gets ζ = 0.)
pub fn with_damped_oscillator<R>(
    methods: &Methods,
    damping: (&'static str, f64),
    f: impl FnOnce(&mut Stepper) -> R,
) -> Result<R, CaseError> {
    oscillator(methods, None, Some(damping), f)
}

fn oscillator<R>(
    methods: &Methods,
    scheme: Option<Box<dyn TimeScheme>>,
    damping: Option<(&'static str, f64)>,
    f: impl FnOnce(&mut Stepper) -> R,
) -> Result<R, CaseError> {
    let mesh = structured::interval(1, 0.0, 1.0);
    let asm = Assembler::new(&mesh);
    let in_use = FilesInUse::resolve(&methods.clone().set("elasticity.rho", 3.0), &[])?;
    let coefs = |name: &str| match name {
        "f" => Some(Coef::constant(vec![0.0])),
        "g" => Some(Coef::scalar(0.0)),
        "nc" => Some(Coef::constant(vec![-1.0])),
        _ => None,
    };
    let binding = Binding::new(Quadrature::default(), vec![("Gamma_C".into(), &[])], 1);
    let mut inst = in_use.forms.instantiate(&coefs, &binding)?;
    // A scheme that applies the damping slot gets 2ζM there: ζ = 0 (undamped) unless asked.
    let slot = crate::settings::get().verify.damping_slot.as_str();
    let damping = damping.or_else(|| in_use.scheme.desc().uses.iter().any(|s| s.name == slot).then_some((slot, 0.0)));
    let given: Vec<Slot> = match damping {
        Some((slot, zeta)) => {
            let mut mass = asm.zero_matrix();
            let mut probe = in_use.forms.instantiate(&coefs, &binding)?;
            let m = probe.take_form("mass").ok_or_else(|| CaseError::Option("the oscillator needs `mass`".into()))?;
            m.tangent(&asm, &[&[0.0, 0.0]], 0, 0.0, &mut mass);
            let mut c = asm.zero_matrix();
            c.add_scaled(2.0 * zeta, &mass);
            vec![(slot, Box::new(MatrixForm { name: slot.into(), matrix: c }))]
        }
        None => Vec::new(),
    };
    let forms = in_use.scheme_forms_with(&mut inst, given)?;
    let mut constraints = Constraints::none(asm.size());
    constraints.fix(1);
    let scheme = match scheme {
        Some(s) => s,
        None => in_use.time_scheme()?,
    };
    let mut stepper = Stepper::new(scheme, &asm, forms, constraints, Structure::General, NewtonOptions::default())?;
    Ok(f(&mut stepper))
}

/// |u(T) − cos T| from u = 1, v = 0.
pub fn oscillator_error(methods: &Methods, dt: f64, t_end: f64) -> Result<f64, CaseError> {
    with_oscillator(methods, |st| final_displacement(st, dt, t_end))?.map(|u| (u - t_end.cos()).abs())
}

/// |u(T) − u_exact(T)| on ü + 2ζu̇ + u = 0 from u = 1, v = 0, with `slot` bound to 2ζM:
/// u = e^{−ζt}(cos ω_d t + ζ/ω_d sin ω_d t), ω_d = √(1 − ζ²).
pub fn damped_oscillator_error(
    methods: &Methods,
    slot: &'static str,
    zeta: f64,
    dt: f64,
    t_end: f64,
) -> Result<f64, CaseError> {
    let wd = (1.0 - zeta * zeta).sqrt();
    let exact = (-zeta * t_end).exp() * ((wd * t_end).cos() + zeta / wd * (wd * t_end).sin());
    with_damped_oscillator(methods, (slot, zeta), |st| final_displacement(st, dt, t_end))?.map(|u| (u - exact).abs())
}

/// u(T) after steps of `dt` from u = 1, v = 0 and the scheme's initial problem.
fn final_displacement(st: &mut Stepper, dt: f64, t_end: f64) -> Result<f64, CaseError> {
    let mut states: Vec<Vec<f64>> = st.desc().states.iter().map(|_| vec![0.0; 2]).collect();
    states[0][0] = 1.0;
    st.initialize(&mut states, 0.0)?;
    let steps = (t_end / dt).round() as usize;
    for k in 0..steps {
        st.step(&mut states, k as f64 * dt, dt)?;
    }
    Ok(states[0][0])
}

/// Spectral radius of the one-step map of the oscillator's states at step `dt` (ω = 1).
pub fn spectral_radius(methods: &Methods, dt: f64) -> Result<f64, CaseError> {
    Ok(spectral_radius_of(&step_map(methods, dt)?))
}

/// The matrix of one step of the oscillator on the states (u, v, a, ...): column j is the step
/// of the j-th unit state.
pub fn step_map(methods: &Methods, dt: f64) -> Result<Vec<Vec<f64>>, CaseError> {
    with_oscillator(methods, |st| -> Result<Vec<Vec<f64>>, CaseError> {
        let m = st.desc().states.len();
        let mut a = vec![vec![0.0; m]; m];
        for j in 0..m {
            let mut states: Vec<Vec<f64>> = (0..m).map(|_| vec![0.0; 2]).collect();
            states[j][0] = 1.0;
            st.step(&mut states, 0.0, dt)?;
            for (i, row) in a.iter_mut().enumerate() {
                row[j] = states[i][0];
            }
        }
        Ok(a)
    })?
}

/// The spectral radius lim ‖Aᵏ‖^(1/k), by 40 normalized squarings (k = 2⁴⁰): exact to
/// ~1e-10 even for the double and triple roots at infinite step (generalized-α, TR-BDF2), where
/// eigenvalue iterations converge slowly.
fn spectral_radius_of(a: &[Vec<f64>]) -> f64 {
    let n = a.len();
    let mut b = a.to_vec();
    let mut log_scale = 0.0;
    for _ in 0..40 {
        let mut c = vec![vec![0.0; n]; n];
        for i in 0..n {
            for j in 0..n {
                c[i][j] = (0..n).map(|k| b[i][k] * b[k][j]).sum();
            }
        }
        let s = c.iter().flatten().fold(0.0f64, |x, v| x.max(v.abs()));
        if s == 0.0 || !s.is_finite() {
            return if s == 0.0 { 0.0 } else { f64::INFINITY };
        }
        c.iter_mut().flatten().for_each(|v| *v /= s);
        b = c;
        // After m squarings A^(2^m) = b · exp(log_scale).
        log_scale = 2.0 * log_scale + s.ln();
    }
    (log_scale / 2f64.powi(40)).exp()
}

/// E = ½(u² + v²) at every step of `steps` steps of size `dt` from u = 1, v = 0 (M = K = 1).
pub fn oscillator_energies(methods: &Methods, dt: f64, steps: usize) -> Result<Vec<f64>, CaseError> {
    with_oscillator(methods, |st| -> Result<Vec<f64>, CaseError> {
        let v = st.desc().states.iter().position(|s| *s == "v").ok_or_else(|| {
            CaseError::Option(format!("the scheme's states {:?} have no velocity `v`", st.desc().states))
        })?;
        let mut states: Vec<Vec<f64>> = st.desc().states.iter().map(|_| vec![0.0; 2]).collect();
        states[0][0] = 1.0;
        st.initialize(&mut states, 0.0)?;
        let energy = |s: &[Vec<f64>]| 0.5 * (s[0][0] * s[0][0] + s[v][0] * s[v][0]);
        let mut out = vec![energy(&states)];
        for k in 0..steps {
            st.step(&mut states, k as f64 * dt, dt)?;
            out.push(energy(&states));
        }
        Ok(out)
    })?
}

/// The scheme's `estimate` over the true local error of one step of `dt` on the oscillator from
/// the exact states at t = 1/2 (u = cos t, v = −sin t, the scheme's initial problem for a): 1
/// where the estimate is asymptotically exact; none for a scheme that declares no estimate.
pub fn estimate_ratio(methods: &Methods, dt: f64) -> Result<Option<f64>, CaseError> {
    with_oscillator(methods, |st| -> Result<Option<f64>, CaseError> {
        if !st.estimate_steps() {
            return Ok(None);
        }
        let t0 = 0.5f64;
        let mut states: Vec<Vec<f64>> = st.desc().states.iter().map(|_| vec![0.0; 2]).collect();
        states[0][0] = t0.cos();
        if let Some(v) = st.desc().states.iter().position(|s| *s == "v") {
            states[v][0] = -t0.sin();
        }
        st.initialize(&mut states, t0)?;
        st.step(&mut states, t0, dt)?;
        let error = states[0][0] - (t0 + dt).cos();
        Ok(st.estimate().map(|e| e[0] / error))
    })?
}
