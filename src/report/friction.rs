//! Section 6 of the report: friction. The library's friction problems at their defaults (the
//! rolling disc against the rigid disc, the sheared block's reaction against Coulomb's bound and
//! Tresca's threshold), and the oblique disc with every library scheme × frictional law (the
//! laws that provide `friction_work`), found in the library, not named here.

use std::fmt::Write;
use std::path::Path;

use crate::driver::Methods;
use crate::error::CaseError;
use crate::problem::run::{Options, run};

/// The library's frictional contact laws: those with a `friction_work` functional.
fn frictional_laws() -> Vec<&'static str> {
    crate::driver::library()
        .iter()
        .filter(|u| u.forms.is_some_and(|f| f.slots.iter().any(|s| s.name == "friction_work")))
        .map(|u| u.name.strip_prefix("contact_").unwrap_or(u.name))
        .collect()
}

pub fn section(out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String, CaseError> {
    let dir = out.join("friction");
    let mut md = String::from("## 6. Friction (`run rolling_disc`, `run shear_block`, `run oblique_disc`)\n\n");
    md.push_str("The rigid-body limits and Coulomb's bound, as the problems state them (`expect` lines; docs/problems.md, Friction):\n\n| run | key | value | expected | relative | within | met |\n|---|---|---|---|---|---|---|\n");
    let runs: [(&str, &str, Methods); 3] = [
        ("rolling_disc", "rolling disc", Methods::default()),
        ("shear_block", "sheared block, Coulomb", Methods::default()),
        (
            "shear_block",
            "sheared block, Tresca s = 0.1",
            Methods { contact: "nitsche_tresca".into(), ..Methods::default() }.set("s", 0.1),
        ),
    ];
    let mut figures = String::new();
    for (k, (problem, label, methods)) in runs.into_iter().enumerate() {
        progress(&format!("friction: {label}"));
        let sub = format!("{problem}_{k}");
        let mut opts = Options::new(problem);
        opts.chosen.contact = methods.contact != Methods::default().contact;
        opts.methods = methods;
        opts.out = Some(dir.join(&sub));
        let s = run(&opts)?.summary;
        let number = |x: Option<f64>| x.map_or("none".to_string(), |x| format!("{x:.6}"));
        for x in s.field::<Vec<crate::problem::summary::Expectation>>("expected")? {
            // A Tresca run is held to its own threshold: Coulomb's ratio is not its law.
            let note = if opts.chosen.contact { " (Coulomb's: not this law)" } else { "" };
            let _ = writeln!(
                md,
                "| {label} | {}{note} | {} | {} | {} | {} | {} |",
                x.key,
                number(x.value),
                number(x.expected),
                x.relative.map_or("none".to_string(), |r| format!("{r:.2e}")),
                x.within,
                if x.met { "yes" } else { "no" }
            );
        }
        if opts.chosen.contact {
            let _ = writeln!(
                md,
                "| {label} | final_tangential | {} | 0.200000 (2 s) | | | |",
                number(s.number("final_tangential"))
            );
        }
        let _ = writeln!(figures, "![{label}](friction/{sub}/{problem}.png)\n");
    }
    md.push('\n');
    md.push_str(&figures);
    // Every scheme × frictional law on the oblique disc, coarse (h = 2) through the first impact.
    md.push_str("The oblique disc (h = 2, Δt = 0.02, t ∈ [5.5, 12]: the first impact and the bounce) with every library scheme and frictional law at their defaults: the frictional work, the largest |E_aug + W_fric − E_aug(0)| (what the scheme's energy law leaves over the law's end-of-step work; docs/mathematics.md §3), the horizontal velocity and spin at the end (thrown at 0.5 without spin), Newton, and ms/step.\n\n| scheme | law | W_fric | max \\|balance\\| | v_x(12) | spin(12) | Newton | ms/step |\n|---|---|---|---|---|---|---|---|\n");
    for scheme in crate::driver::all_schemes() {
        for law in frictional_laws() {
            progress(&format!("friction: oblique disc, {scheme} {law}"));
            let mut opts = Options::new("oblique_disc");
            opts.methods = Methods { scheme: scheme.into(), contact: law.into(), ..Methods::default() }.set("h", 2.0);
            opts.chosen.scheme = true;
            opts.chosen.contact = true;
            opts.t_start = Some(5.5);
            let row = match super::past_the_guard(opts.methods.clone(), |methods| {
                run(&Options { methods, ..opts.clone() })
            }) {
                Ok((r, note)) => {
                    let s = r.summary;
                    let get = |k: &str| s.number(k).unwrap_or(f64::NAN);
                    let note = note.map_or(String::new(), |n| format!(" ({n})"));
                    format!(
                        "| {scheme} | {law} | {:.4} | {:.2e}{note} | {:.4} | {:.4} | {} | {:.2} |",
                        get("work_of_friction"),
                        get("balance_max"),
                        get("vx_final"),
                        get("spin_final"),
                        get("newton_total"),
                        1e3 * get("seconds_per_step")
                    )
                }
                Err(e) => format!(
                    "| {scheme} | {law} | failed: {} | | | | | |",
                    e.to_string().replace('|', "/").lines().next().unwrap_or("")
                ),
            };
            let _ = writeln!(md, "{row}");
        }
    }
    md.push('\n');
    Ok(md)
}
