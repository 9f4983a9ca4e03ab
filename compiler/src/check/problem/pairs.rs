//! Contact pairs: `contact Gamma_a with Gamma_b within R by segments`, two known regions of two
//! bodies.

use super::{Names, scalar, unknown_among};
use crate::check::types::Checker;
use crate::diagnostic::Diagnostic;
use crate::syntax::ast::Problem;

/// How a pair's law is integrated: `by elements` (each own facet whole, the default) or
/// `by segments`.
pub const PAIR_INTEGRATION: &[&str] = &["elements", "segments"];

pub(super) fn check(c: &mut Checker, p: &Problem, constants: &Names, diags: &mut Vec<Diagnostic>) {
    let regions: Vec<&str> = p.regions.iter().map(|r| r.name.name.as_str()).collect();
    for pair in &p.pairs {
        for side in [&pair.own, &pair.facing] {
            if !regions.contains(&side.name.as_str()) {
                diags.push(unknown_among(side, regions.iter().copied(), "region"));
            }
        }
        if pair.own.name == pair.facing.name {
            diags.push(
                Diagnostic::error("E0103", "a region in contact with itself", pair.facing.span, "the same region")
                    .with_label(pair.own.span, "as this one")
                    .with_note("self-contact needs a search that skips the point's own neighbourhood, which pairs do not have yet")
                    .with_help("a pair joins two regions of two bodies: `contact Gamma_a with Gamma_b`"),
            );
        }
        if let Some(reach) = &pair.reach {
            scalar(c, reach, constants, diags, false);
        }
        if let Some(by) = &pair.by
            && !PAIR_INTEGRATION.contains(&by.name.as_str())
        {
            diags.push(unknown_among(by, PAIR_INTEGRATION.iter().copied(), "pair integration").with_note(
                "`by elements` integrates over each own facet with the law's rule; `by segments` (2D) cuts each facet where its points' facing point crosses an end of a facing facet, and passes the contact patch test on non-matching meshes",
            ));
        }
    }
    if let (Some(o), Some(pair)) = (p.obstacles.first(), p.pairs.first()) {
        diags.push(
            Diagnostic::error("E0103", "an obstacle and a contact pair", o.span, "an obstacle")
                .with_label(pair.span, "and a pair")
                .with_note("the run's contact law is either an obstacle's law or a pair's law; both in one run is not supported yet")
                .with_help("hold the foundation by a Dirichlet condition, or model the obstacle as a body"),
        );
    }
}
