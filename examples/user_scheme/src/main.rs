//! A scheme of our own, `wbz.wf`, compiled into this crate and run on the library's cases: the
//! compressed bar, and the bouncing disc on a Gmsh mesh given as the first argument.

signorini::forms!(mod wbz = "wbz.wf");

use signorini::cases::{bar, disc};
use signorini::driver::Methods;
use signorini::problem::run::Options;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let methods = Methods { scheme: "wbz".into(), compiled: vec![&wbz::UNIT], ..Methods::default() };
    let methods = methods.set("alpha_b", -0.1);
    let r = bar::run(&Options { methods: methods.clone(), ..bar::options() })?.summary;
    println!("bar: err_u {:.4}, E_aug {:.6} -> {:.6}", r.err_linf_l2_u, r.energy_aug_initial, r.energy_aug_final);
    if let Some(mesh) = std::env::args().nth(1) {
        let opts = Options { methods, mesh: Some(mesh.into()), t_end: Some(10.0), ..disc::options() };
        let r = disc::run(&opts)?.summary;
        let first = r.first_contact.map_or("never".into(), |t| format!("{t:.2}"));
        println!("disc: {} dofs, first contact at t = {first}, max penetration {:.3e}", r.dofs, r.max_penetration);
    }
    Ok(())
}
