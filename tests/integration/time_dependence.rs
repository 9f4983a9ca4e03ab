//! A form knows whether it changes with time other than through its fields: the compiler sees
//! whether its integrands read `t` or a coef, and a coef whether it is a function of time.
//! The stepper assembles a load that does not once.

use signorini::forms::elasticity::{Coefficients, Load, Params};
use signorini::runtime::fem::kernel::{Coef, Form};

fn load(f: Coef) -> Load {
    let p = Params::default().with("E", 1.0).and_then(|p| p.with("nu", 0.3)).and_then(|p| p.with("rho", 1.0));
    Load::new(&p.expect("valid parameters"), &Coefficients { f })
}

#[test]
fn a_load_is_steady_exactly_when_its_coefs_are() {
    assert!(!load(Coef::constant(vec![0.0, -1.0])).time_dependent());
    assert!(!load(Coef::of_position(2, |x, out| out.copy_from_slice(&[x[0], 0.0]))).time_dependent());
    assert!(load(Coef::function(2, |_, t, out| out.copy_from_slice(&[0.0, -t]))).time_dependent());
}
