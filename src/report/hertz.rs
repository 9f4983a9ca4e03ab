//! Section 5 of the report: the Hertz cases. Static contact on every level of the graded
//! meshes (observed orders of the errors against Hertz), and the impact at several speeds.

use std::fmt::Write;
use std::path::Path;

use crate::driver::Methods;
use crate::error::CaseError;
use crate::problem::run::{Options, run};

/// The finest level the report solves in 2D and in 3D (level 3 in 3D has 132k unknowns: minutes
/// per Newton solve).
const FINEST: [usize; 2] = [3, 2];
/// Impact speeds of the regime study (on the coarsest mesh), fastest first; the last is the
/// problem's default.
const SPEEDS: [f64; 3] = [0.02, 0.005, 0.0025];

/// log(e_{k−1}/e_k) / log(h_{k−1}/h_k) for successive levels.
fn orders(errors: &[f64], sizes: &[f64]) -> Vec<String> {
    errors
        .windows(2)
        .zip(sizes.windows(2))
        .map(|(e, h)| format!("{:.2}", (e[0].abs() / e[1].abs()).ln() / (h[0] / h[1]).ln()))
        .collect()
}

pub fn section(out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String, CaseError> {
    let mut md =
        String::from("## 5. Hertz validation (`run hertz_cylinder`, `run hertz_ball`, `run hertz_impact`)\n\n");
    md.push_str("Half cylinder (2D, plane strain) and quarter ball (3D) of radius 10, E = 50, ν = 0.25 (λ = μ = 20), γ0 = 5000, pressed");
    md.push_str(" onto the plane by a body force whose resultant gives Hertz's a = R/10 (forms/problems/hertz_cylinder.wf, hertz_ball.wf); graded Gmsh meshes (assets/meshes/hertz_*.geo: one cell size h_c in the contact zone, each level divides every size by 2 in 2D, √2 in 3D). a: the half-width (2D) or radius (3D) of the zone where the pressure is positive; p₀: the centre pressure; profile: ‖p_h − p‖/‖p‖ in L² on Γ_C's projection onto the plane. h: the smallest cell diameter on Γ_C. Errors are against Hertz, whose own error, O((a/R)²), does not shrink with h: the orders log(e_{k−1}/e_k)/log(h_{k−1}/h_k) fall once the discretisation error reaches it (the 2D peak pressure already has).\n\n");
    let contacts = &crate::settings::get().verify.contacts;
    for (dim, problem, size) in [(2, "hertz_cylinder", "half_width"), (3, "hertz_ball", "contact_radius")] {
        let levels = FINEST[dim - 2] + 1;
        for contact in contacts {
            let _ = writeln!(md, "### {dim}D, {contact}\n");
            md.push_str("| level | unknowns | h | a (error) | p₀ (error) | profile error | Newton | s |\n|---|---|---|---|---|---|---|---|\n");
            let mut errors: [Vec<f64>; 3] = Default::default();
            let mut sizes = Vec::new();
            let mut figure = String::new();
            for level in 0..levels {
                progress(&format!("{problem} {contact} level {level}"));
                let dir = out.join("hertz").join(format!("static_{dim}d_{contact}_{level}"));
                let mut opts = Options::new(problem);
                opts.methods = Methods { contact: contact.clone(), ..Methods::default() }.set("level", level as f64);
                opts.chosen.contact = true;
                opts.out = Some(dir);
                let s = run(&opts)?.summary;
                let get = |k: &str| s.number(k).unwrap_or(f64::NAN);
                let (a, a_err, p0, p0_err) =
                    (get(size), get(&format!("{size}_error")), get("peak_pressure"), get("peak_pressure_error"));
                let (profile, h) = (get("profile_l2_error"), get("h_contact"));
                let _ = writeln!(
                    md,
                    "| {level} | {} | {h:.3} | {a:.4} ({:+.2}%) | {p0:.4} ({:+.2}%) | {:.2}% | {} | {:.1} |",
                    get("dofs"),
                    100.0 * a_err,
                    100.0 * p0_err,
                    100.0 * profile,
                    get("newton_total"),
                    get("wall_seconds")
                );
                sizes.push(h);
                errors[0].push(a_err);
                errors[1].push(p0_err);
                errors[2].push(profile);
                figure = format!("![profile](hertz/static_{dim}d_{contact}_{level}/profile.png)\n");
            }
            let _ = writeln!(
                md,
                "\nObserved orders (successive levels): a {}; p₀ {}; profile {}.\n\nFinest level:\n\n{figure}",
                orders(&errors[0], &sizes).join(", "),
                orders(&errors[1], &sizes).join(", "),
                orders(&errors[2], &sizes).join(", ")
            );
        }
    }
    md.push_str("### Impact (`run hertz_impact`)\n\nThe quarter ball hits the plane at speed v without gravity (the library's default scheme and contact law, Δt = Hertz's contact time / 200). Hertz's");
    md.push_str(" impact formulas are quasi-static; the regime columns say how far a run is from that limit (δ_max/R and the contact time over R/c_p), and the errors shrink with v.\n\n");
    md.push_str("| level | v | δ_max/R | t_c c_p/R | contact time (error) | peak force (error) | contact radius (error) | restitution | s |\n|---|---|---|---|---|---|---|---|---|\n");
    let mut runs: Vec<(usize, f64)> = SPEEDS.iter().map(|&v| (0, v)).collect();
    runs.push((1, SPEEDS[2]));
    let mut figure = String::new();
    for (level, speed) in runs {
        progress(&format!("hertz_impact level {level} v = {speed}"));
        let name = format!("impact_{level}_{speed}");
        let mut opts = Options::new("hertz_impact");
        opts.methods = Methods::default().set("level", level as f64).set("speed", speed);
        opts.out = Some(out.join("hertz").join(&name));
        let s = run(&opts)?.summary;
        let get = |k: &str| s.number(k).unwrap_or(f64::NAN);
        let _ = writeln!(
            md,
            "| {level} | {speed} | {:.4} | {:.1} | {:.3} ({:+.2}%) | {:.4} ({:+.2}%) | {:.4} ({:+.2}%) | {:.5} | {:.0} |",
            get("indentation_ratio"),
            get("contact_time_over_wave_time"),
            get("contact_duration"),
            100.0 * get("contact_duration_error"),
            get("peak_force"),
            100.0 * get("peak_force_error"),
            get("contact_radius"),
            100.0 * get("contact_radius_error"),
            get("restitution"),
            get("wall_seconds")
        );
        figure = format!("![force](hertz/{name}/hertz_impact.png)\n");
    }
    let _ = writeln!(md, "\nThe last run's force history against Hertz's:\n\n{figure}");
    Ok(md)
}
