//! A problem's bodies on its mesh: the generated ones placed beside the mesh file's cells (each
//! keeps its own nodes: bodies touch only through contact), each body's cells found (a physical
//! group of the file's, or its generator's), and a check that they share out the mesh's cells.

use super::ProblemFile;
use super::expr::Exprs;
use crate::compiler::Diagnostic;
use crate::compiler::syntax::ast::{BodySource, MeshSource, Problem};
use crate::error::CaseError;
use crate::runtime::fem::mesh::Mesh;

/// The problem's first source of cells: its `mesh` line, or with none its first body's
/// generator.
pub(super) fn primary(p: &Problem) -> Option<MeshSource> {
    p.mesh.first().cloned().or_else(|| {
        p.bodies.iter().find_map(|b| match &b.source {
            BodySource::Generator(call) => Some(MeshSource::Generator(call.clone())),
            BodySource::Group { .. } => None,
        })
    })
}

/// Places the bodies' generated meshes after `mesh`'s cells (the first of them is `mesh` itself
/// when the problem has no `mesh` line), adding each to `label`; the cells of every body, in
/// the problem's order.
pub(super) fn place(
    pf: &ProblemFile,
    ex: &mut Exprs,
    mesh: &mut Mesh,
    label: &mut String,
) -> Result<Vec<(String, Vec<u32>)>, CaseError> {
    let p = pf.problem();
    if p.bodies.is_empty() {
        return Ok(Vec::new());
    }
    let mut first = p.mesh.is_empty();
    let mut out = Vec::new();
    for b in &p.bodies {
        let cells = match &b.source {
            BodySource::Generator(_) if first => {
                first = false;
                (0..mesh.num_cells() as u32).collect()
            }
            BodySource::Generator(call) => {
                let (placed, placed_label) = super::generate::generate(pf, ex, call)?;
                if placed.kind != mesh.kind {
                    return Err(pf.render(
                        Diagnostic::error(
                            "E0301",
                            format!(
                                "body `{}` has cells of kind {}, the problem's other bodies {}",
                                b.name.name,
                                placed.kind.name(),
                                mesh.kind.name()
                            ),
                            call.span,
                            "another element",
                        )
                        .with_help(
                            "give every body's generator the same `degree` (the bodies share one space of functions)",
                        ),
                    ));
                }
                label.push_str(&format!(" + {placed_label}"));
                mesh.append(&placed).collect()
            }
            BodySource::Group { name, span } => match mesh.cell_groups.iter().find(|(g, _)| g == name) {
                Some((_, cells)) => cells.clone(),
                None => {
                    let groups: Vec<&str> = mesh.cell_groups.iter().map(|(g, _)| g.as_str()).collect();
                    let mut d = Diagnostic::error(
                        "E0101",
                        format!("body `{}`: {label} has no group of cells \"{name}\"", b.name.name),
                        *span,
                        "no such physical group",
                    );
                    if let Some(close) = crate::compiler::check::suggest_name(name, groups.iter().copied()) {
                        d = d.with_help(format!("did you mean group \"{close}\"?"));
                    }
                    let list = if groups.is_empty() { "none".to_string() } else { groups.join(", ") };
                    return Err(pf.render(d.with_note(format!("the mesh's groups of cells: {list}"))));
                }
            },
        };
        out.push((b.name.name.clone(), cells));
    }
    share_out(pf, mesh, &out, label)?;
    Ok(out)
}

/// Every cell in one body: a cell in two, or in none, is an error at the body (or the problem).
fn share_out(pf: &ProblemFile, mesh: &Mesh, bodies: &[(String, Vec<u32>)], label: &str) -> Result<(), CaseError> {
    let p = pf.problem();
    let mut owner: Vec<Option<usize>> = vec![None; mesh.num_cells()];
    for (k, (name, cells)) in bodies.iter().enumerate() {
        for &c in cells {
            if let Some(other) = owner[c as usize].replace(k) {
                return Err(pf.render(
                    Diagnostic::error(
                        "E0102",
                        format!("cell {c} of {label} is in body `{}` and in body `{name}`", bodies[other].0),
                        p.bodies[k].name.span,
                        "shares cells with an earlier body",
                    )
                    .with_help("a cell belongs to one body: give each body its own physical group"),
                ));
            }
        }
    }
    let orphans = owner.iter().filter(|o| o.is_none()).count();
    if orphans > 0 {
        let groups: Vec<&str> = mesh.cell_groups.iter().map(|(g, _)| g.as_str()).collect();
        let list = if groups.is_empty() { "none".to_string() } else { groups.join(", ") };
        return Err(pf.render(
            Diagnostic::error(
                "E0101",
                format!("{orphans} of the {} cells of {label} are in no body", mesh.num_cells()),
                p.bodies[0].name.span,
                "the bodies leave cells out",
            )
            .with_note(format!("the mesh's groups of cells: {list}"))
            .with_help("declare a body for each physical group of cells (`body rest = group \"...\"`)"),
        ));
    }
    Ok(())
}

/// A region declared in body `body`: its facets on the body's cells.
pub(super) fn cut(
    facets: Vec<crate::runtime::fem::mesh::Facet>,
    body: &str,
    bodies: &[(String, Vec<u32>)],
    cells: usize,
) -> Vec<crate::runtime::fem::mesh::Facet> {
    let Some((_, list)) = bodies.iter().find(|(b, _)| b == body) else { return facets };
    let mut mine = vec![false; cells];
    list.iter().for_each(|&c| mine[c as usize] = true);
    facets.into_iter().filter(|f| mine[f.cell as usize]).collect()
}
