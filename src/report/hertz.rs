//! Section 5 of the report: the Hertz cases of forms/library.toml's `[report]`. Static contact
//! on every level of the graded meshes up to the finest the table asks for (observed orders of
//! the errors against Hertz), and the impact at several speeds.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use super::table::Table;
use crate::driver::{Methods, ParamValue};
use crate::error::CaseError;
use crate::numbers::readable;
use crate::problem::run::{Options, run};

/// Impact speeds of the regime study (on the coarsest mesh), fastest first, before the
/// problem's own (its default `speed`, also run on the next level).
const SPEEDS: [f64; 2] = [0.02, 0.005];

/// log(e_{k−1}/e_k) / log(h_{k−1}/h_k) for successive levels.
fn orders(errors: &[f64], sizes: &[f64]) -> Vec<String> {
    errors
        .windows(2)
        .zip(sizes.windows(2))
        .map(|(e, h)| format!("{:.2}", (e[0].abs() / e[1].abs()).ln() / (h[0] / h[1]).ln()))
        .collect()
}

pub fn section(out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String, CaseError> {
    let settings = crate::settings::get();
    let (hertz, impact) = (&settings.report.hertz, &settings.report.hertz_impact);
    let runs: Vec<String> = hertz.iter().map(|h| &h.problem).chain([impact]).map(|p| format!("`run {p}`")).collect();
    let mut md = format!("## 5. Hertz validation ({})\n\n", runs.join(", "));
    let mut body = String::new();
    let mut statics: Option<BTreeMap<String, ParamValue>> = None;
    let contacts = &settings.verify.contacts;
    for h in hertz {
        let (problem, size, levels) = (&h.problem, &h.size, h.finest + 1);
        for contact in contacts {
            let _ = writeln!(body, "### {problem}, {contact}\n");
            let mut table = Table::new(&[
                "level",
                "unknowns",
                "h",
                "a (error)",
                "p₀ (error)",
                "profile error",
                "Newton iterations",
                "wall time (s)",
            ]);
            let mut errors: [Vec<f64>; 3] = Default::default();
            let mut sizes = Vec::new();
            let mut figure = String::new();
            for level in 0..levels {
                progress(&format!("{problem} {contact} level {level}"));
                let dir = out.join("hertz").join(format!("{problem}_{contact}_{level}"));
                let mut opts = Options::new(problem);
                opts.methods = Methods { contact: contact.clone(), ..Methods::default() }.set("level", level as f64);
                opts.chosen.contact = true;
                opts.out = Some(dir);
                let s = run(&opts)?.summary;
                if statics.is_none() {
                    statics = Some(s.field("params")?);
                }
                let get = |k: &str| s.number(k).unwrap_or(f64::NAN);
                let (a, a_err, p0, p0_err) =
                    (get(size), get(&format!("{size}_error")), get("peak_pressure"), get("peak_pressure_error"));
                let (profile, h) = (get("profile_l2_error"), get("h_contact"));
                table.row([
                    level.to_string(),
                    get("dofs").to_string(),
                    format!("{h:.3}"),
                    format!("{a:.4} ({:+.2} %)", 100.0 * a_err),
                    format!("{p0:.4} ({:+.2} %)", 100.0 * p0_err),
                    format!("{:.2} %", 100.0 * profile),
                    get("newton_total").to_string(),
                    readable(get("wall_seconds")),
                ]);
                sizes.push(h);
                errors[0].push(a_err);
                errors[1].push(p0_err);
                errors[2].push(profile);
                figure = format!("![profile](hertz/{problem}_{contact}_{level}/profile.png)\n");
            }
            body.push_str(&table.markdown());
            let _ = writeln!(
                body,
                "\nObserved orders (successive levels): a {}; p₀ {}; profile {}.\n\nFinest level:\n\n{figure}",
                orders(&errors[0], &sizes).join(", "),
                orders(&errors[1], &sizes).join(", "),
                orders(&errors[2], &sizes).join(", ")
            );
        }
    }
    let params = statics.map_or_else(String::new, |p| super::params_by_file(&p, &["level"]));
    let files: Vec<String> = hertz.iter().map(|h| format!("forms/problems/{}.wf", h.problem)).collect();
    md.push_str("A half cylinder (2D, plane strain) and a quarter ball (3D) of radius R pressed");
    let _ = write!(
        md,
        " onto the plane by a body force whose resultant gives Hertz's a = ratio · R ({}; run with {params}); graded Gmsh meshes (assets/meshes/hertz_*.geo: one cell size h_c in the contact zone, each level divides every size by 2 in 2D, √2 in 3D). a: the half-width (2D) or radius (3D) of the zone where the pressure is positive; p₀: the centre pressure; profile: ‖p_h − p‖/‖p‖ in L² on Γ_C's projection onto the plane. h: the smallest cell diameter on Γ_C. Errors are against Hertz, whose own error, O((a/R)²), does not shrink with h: the orders log(e_{{k−1}}/e_k)/log(h_{{k−1}}/h_k) fall once the discretisation error reaches it (the 2D peak pressure already has).\n\n",
        files.join(", ")
    );
    md.push_str(&body);
    let mut table = Table::new(&[
        "level",
        "v",
        "δ_max/R",
        "t_c c_p/R",
        "contact time (error)",
        "peak force (error)",
        "contact radius (error)",
        "restitution",
        "wall time (s)",
    ]);
    let mut impact_params: Option<BTreeMap<String, ParamValue>> = None;
    let mut runs: Vec<(usize, Option<f64>)> = SPEEDS.iter().map(|&v| (0, Some(v))).collect();
    runs.extend([(0, None), (1, None)]);
    let mut figure = String::new();
    for (level, speed) in runs {
        let shown = speed.map_or("its own".to_string(), |v| v.to_string());
        progress(&format!("{impact} level {level} v = {shown}"));
        let name = format!("impact_{level}_{}", speed.map_or("default".to_string(), |v| v.to_string()));
        let mut opts = Options::new(impact);
        opts.methods = Methods::default().set("level", level as f64);
        if let Some(v) = speed {
            opts.methods = opts.methods.set("speed", v);
        }
        opts.out = Some(out.join("hertz").join(&name));
        let s = run(&opts)?.summary;
        let params: BTreeMap<String, ParamValue> = s.field("params")?;
        let speed = params.get(&format!("{impact}.speed")).map_or(f64::NAN, |p| p.value);
        impact_params.get_or_insert(params);
        let get = |k: &str| s.number(k).unwrap_or(f64::NAN);
        let with_error = |value: &str, digits: usize| {
            format!("{:.digits$} ({:+.2} %)", get(value), 100.0 * get(&format!("{value}_error")))
        };
        table.row([
            level.to_string(),
            readable(speed),
            format!("{:.4}", get("indentation_ratio")),
            format!("{:.1}", get("contact_time_over_wave_time")),
            with_error("contact_duration", 3),
            with_error("peak_force", 4),
            with_error("contact_radius", 4),
            format!("{:.5}", get("restitution")),
            readable(get("wall_seconds")),
        ]);
        figure = format!("![force](hertz/{name}/{impact}.png)\n");
    }
    let params = impact_params.map_or_else(String::new, |p| super::params_by_file(&p, &["level", "speed"]));
    let _ = write!(
        md,
        "### Impact (`run {impact}`)\n\nThe quarter ball hits the plane at speed v without gravity (Δt = Hertz's contact time / steps; run with {params}). Hertz's"
    );
    md.push_str(" impact formulas are quasi-static; the regime columns say how far a run is from that limit (δ_max/R and the contact time over R/c_p), and the errors shrink with v.\n\n");
    md.push_str(&table.markdown());
    let _ = writeln!(md, "\nThe last run's force history against Hertz's:\n\n{figure}");
    Ok(md)
}
