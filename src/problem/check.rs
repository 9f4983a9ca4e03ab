//! A problem bound without running it: `signorini check` on a problem file, and the params a
//! run would use.

use super::options::Options;
use super::reference::reference;
use super::resolve::bound;
use crate::error::CaseError;
use crate::runtime::fem::mesh::CellSize;

/// Binds a problem with the library's defaults without running it: its params, the files in use
/// and their coefs, the mesh with its regions, the coefs' and initial fields' expressions in the
/// problem's dimension, the conditions of its `expect` lines (`signorini check` on a problem
/// file). Returns one line saying what was
/// checked and bound: the mesh, the regions with their facets, the unknowns, the files in use.
pub fn check(problem: &str) -> Result<String, CaseError> {
    let opts = Options::new(problem);
    bound(&opts, |pf, _, ex, in_use, read_mesh| {
        let p = pf.problem();
        reference(pf, ex.dim())?;
        super::bind::settings(pf, ex, &p.run)?;
        super::bind::settings(pf, ex, &p.quadrature)?;
        let (mesh, label) = super::bind::mesh(pf, ex, None, CellSize::Diameter, read_mesh)?;
        super::bind::coefs(pf, ex)?;
        super::bind::coef_vals(pf, ex)?;
        super::bind::initial(pf, ex, &mesh, "u", 0.0)?;
        super::bind::initial(pf, ex, &mesh, "v", 0.0)?;
        // The names an `expect ... when` reads, as a run resolves them.
        super::summary::applies(pf, ex, &in_use.forms.params)?;
        let regions: Vec<String> = p
            .regions
            .iter()
            .map(|r| {
                let n = mesh.region(&r.name.name).map_or(0, |g| g.facets.len());
                format!("{} ({n} facet{})", r.name.name, if n == 1 { "" } else { "s" })
            })
            .collect();
        let bodies: Vec<String> = mesh
            .bodies
            .iter()
            .map(|b| {
                let n = b.cells.iter().filter(|&&c| c).count();
                format!("{} ({n} cell{})", b.name, if n == 1 { "" } else { "s" })
            })
            .collect();
        let bodies = if bodies.is_empty() { String::new() } else { format!("; bodies {}", bodies.join(", ")) };
        let forms = &in_use.forms;
        let files: Vec<String> = std::iter::once(format!("{} (scheme)", in_use.scheme_name()))
            .chain(forms.units.iter().enumerate().map(|(i, u)| {
                let pairs: Vec<&str> = forms.pairs.iter().filter(|g| g.unit == i).map(|g| g.label.as_str()).collect();
                let role = if i == 0 {
                    "material".to_string()
                } else if i == forms.contact {
                    "contact".to_string()
                } else if !pairs.is_empty() {
                    format!("contact: {}", pairs.join(", "))
                } else {
                    "forms".to_string()
                };
                format!("{} ({role})", u.name())
            }))
            .collect();
        Ok(format!(
            "{}: problem `{}` checked and bound: {}D mesh {label}, {} nodes, {} cells, {} unknowns{bodies}; regions {}; files in use {}",
            pf.file,
            pf.name(),
            mesh.dim(),
            mesh.num_nodes(),
            mesh.num_cells(),
            mesh.num_nodes() * mesh.dim(),
            if regions.is_empty() { "none".to_string() } else { regions.join(", ") },
            files.join(", ")
        ))
    })
}

/// The params of the files a run of `opts` would use, with their values and where each comes
/// from (the files' defaults, the problem's `set`, the user), without building anything.
pub fn params_in_use(
    opts: &Options,
) -> Result<std::collections::BTreeMap<String, crate::driver::ParamValue>, CaseError> {
    bound(opts, |_, _, _, in_use, _| Ok(in_use.forms.params.values()))
}
