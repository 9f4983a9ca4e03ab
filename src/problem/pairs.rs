//! A problem's contact pairs bound to its mesh: `contact Gamma_a with Gamma_b within R by
//! segments`, two regions of two bodies, how far the facing points are looked for, and how the
//! law is integrated.

use super::ProblemFile;
use super::expr::Exprs;
use crate::compiler::Diagnostic;
use crate::compiler::syntax::ast::ContactPair;
use crate::error::CaseError;
use crate::runtime::fem::mesh::{Facet, Mesh};
use crate::runtime::fem::pair::PairRegions;

/// How far a pair looks for facing points when its problem does not say: this many times the
/// largest cell of its two surfaces.
const REACH_IN_CELLS: f64 = 3.0;

/// The problem's pairs on `mesh`, each region a body's, the two bodies distinct.
pub fn surfaces(pf: &ProblemFile, ex: &mut Exprs, mesh: &Mesh) -> Result<Vec<PairRegions>, CaseError> {
    let mut out = Vec::new();
    for pair in &pf.problem().pairs {
        let own = side(pf, mesh, pair, true)?;
        let facing = side(pf, mesh, pair, false)?;
        let largest = own.iter().chain(facing).map(|f| mesh.cell_size(f.cell as usize)).fold(0.0, f64::max);
        let reach = match &pair.reach {
            Some(e) => {
                let r = ex.scalar(e).map_err(|d| pf.render(*d))?;
                if !(r > 0.0 && r.is_finite()) {
                    return Err(pf.render(Diagnostic::error(
                        "E0103",
                        format!("a pair's reach of {r}"),
                        e.span,
                        "not a positive distance",
                    )));
                }
                r
            }
            None => REACH_IN_CELLS * largest,
        };
        let segmented = pair.by.as_ref().is_some_and(|b| b.name == "segments");
        if segmented && mesh.dim() != 2 {
            let by = pair.by.as_ref().map_or(pair.span, |b| b.span);
            return Err(pf.render(
                Diagnostic::error("E0103", "a pair integrated by segments in 3D", by, "2D only")
                    .with_note("in 3D the pieces of a facet are the polygons where the facing facets overlap it, which pairs do not clip yet")
                    .with_help("drop `by segments`: the pair is then integrated facet by facet"),
            ));
        }
        out.push(PairRegions { own: pair.own.name.clone(), facing: pair.facing.name.clone(), reach, segmented });
    }
    Ok(out)
}

/// How deep, in cells, a surface may start inside the body it faces: a law's penalty carries a
/// load at a small overlap (a fraction of a cell), a misplaced body overlaps by much more.
const OVERLAP_IN_CELLS: f64 = 0.5;

/// Refuses a start with the bodies of a pair overlapping by more than [`OVERLAP_IN_CELLS`] of
/// a cell on the configuration x + `u0` (a time run's initial u; zero where it is a guess), at
/// the pair and with where.
pub fn check_overlap(pf: &ProblemFile, mesh: &Mesh, pairs: &[PairRegions], u0: &[f64]) -> Result<(), CaseError> {
    for (pair, regions) in pf.problem().pairs.iter().zip(pairs) {
        let Some(o) = regions.on(mesh).deepest_overlap(mesh, u0) else { continue };
        if o.depth > OVERLAP_IN_CELLS * o.cell_size {
            let at: Vec<String> = o.point.iter().map(|c| format!("{c:.6}")).collect();
            return Err(pf.render(
                Diagnostic::error(
                    "E0103",
                    format!(
                        "the bodies of this pair overlap at the start: a node of `{}` at ({}) is {:.3e} inside the body of `{}`",
                        pair.own.name,
                        at.join(", "),
                        o.depth,
                        pair.facing.name
                    ),
                    pair.span,
                    format!("more than half its cell ({:.3e}) deep", o.cell_size),
                )
                .with_help(
                    "place the bodies apart or touching (and the initial u): a law carries a load at an overlap of a fraction of a cell, not more",
                ),
            ));
        }
    }
    Ok(())
}

/// The facets of one side of `pair`, all of one body, not the other side's body.
fn side<'m>(pf: &ProblemFile, mesh: &'m Mesh, pair: &ContactPair, own: bool) -> Result<&'m [Facet], CaseError> {
    let (name, other) = if own { (&pair.own, &pair.facing) } else { (&pair.facing, &pair.own) };
    let located = |what: String, label: &str, help: &str| {
        pf.render(Diagnostic::error("E0103", what, name.span, label).with_help(help.to_string()))
    };
    let facets = mesh.region(&name.name).map(|r| r.facets.as_slice()).unwrap_or(&[]);
    if facets.is_empty() {
        return Err(located(
            format!("region `{}` of a contact pair has no facet", name.name),
            "empty on the mesh",
            "a pair joins two boundary regions that hold facets",
        ));
    }
    if mesh.bodies.is_empty() {
        return Err(located(
            "a contact pair in a problem of one body".into(),
            "no body to pair with another",
            "declare the bodies: `body NAME = group \"...\"` (or a generator), one for each side",
        ));
    }
    let body_of = |facets: &[Facet]| {
        let first = facets[0].cell as usize;
        let body = mesh.bodies.iter().position(|b| b.cells[first])?;
        facets.iter().all(|f| mesh.bodies[body].cells[f.cell as usize]).then_some(body)
    };
    let Some(body) = body_of(facets) else {
        return Err(located(
            format!("region `{}` of a contact pair spans several bodies (or none)", name.name),
            "not one body's",
            "cut the region to one body: declare it inside the body's braces",
        ));
    };
    let other_facets = mesh.region(&other.name).map(|r| r.facets.as_slice()).unwrap_or(&[]);
    if !other_facets.is_empty() && body_of(other_facets) == Some(body) {
        return Err(pf.render(
            Diagnostic::error(
                "E0103",
                format!("both regions of a contact pair are body `{}`'s", mesh.bodies[body].name),
                pair.span,
                "one body",
            )
            .with_note(
                "self-contact needs a search that skips the point's own neighbourhood, which pairs do not have yet",
            )
            .with_help("pair two bodies' regions"),
        ));
    }
    Ok(facets)
}
