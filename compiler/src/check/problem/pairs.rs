//! Contact pairs: `contact Gamma_a with Gamma_b within R by segments`, two known regions of two
//! bodies.

use super::{Names, distinct, scalar, unknown_among};
use crate::check::types::Checker;
use crate::diagnostic::Diagnostic;
use crate::syntax::ast::{ContactPair, Problem};

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
        block(c, pair, constants, diags);
        if let Some(by) = &pair.by
            && !PAIR_INTEGRATION.contains(&by.name.as_str())
        {
            diags.push(unknown_among(by, PAIR_INTEGRATION.iter().copied(), "pair integration").with_note(
                "`by elements` integrates over each own facet with the law's rule; `by segments` (2D) cuts each facet where its points' facing point crosses an end of a facing facet, and passes the contact patch test on non-matching meshes",
            ));
        }
    }
}

/// A pair's block: `bind contact = LAW` once, and its `set` values (params of that law, which
/// the binding checks) numbers of the problem's.
fn block(c: &mut Checker, pair: &ContactPair, constants: &Names, diags: &mut Vec<Diagnostic>) {
    for (k, b) in pair.binds.iter().enumerate() {
        if b.role.name != "contact" {
            diags.push(unknown_among(&b.role, ["contact"].into_iter(), "pair role").with_note(
                "a pair's block binds its own contact law; the other roles are the problem's: bind them at its top level",
            ));
        } else if let Some(first) = pair.binds[..k].iter().find(|f| f.role.name == "contact") {
            diags.push(
                Diagnostic::error("E0103", "`contact` bound twice", b.role.span, "again here")
                    .with_label(first.role.span, "first here"),
            );
        }
    }
    distinct(pair.sets.iter().map(|d| &d.name), "`set` of a param", diags);
    for d in &pair.sets {
        scalar(c, &d.value, constants, diags, false);
    }
}
