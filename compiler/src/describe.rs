//! A compiled unit as the runtime reads it (`signorini_descriptors`): its params, coefs and
//! form slots, with their docs and where they are declared. Generated code prints these
//! (`codegen`); a file interpreted at run time is described by them as built. A scheme's
//! description is its layout (`scheme::layout`).

use signorini_descriptors::{CoefInfo, ParamInfo, ParamRange, SlotInfo};

use crate::docs;
use crate::program::Program;
use crate::scheme::SchemeIr;
use crate::source::{SourceMap, Span};

/// A param declared at `span` by `owner` (a file stem or a scheme).
fn param(
    sources: &SourceMap,
    name: &str,
    default: f64,
    range: Option<ParamRange>,
    span: Span,
    owner: &str,
) -> ParamInfo {
    ParamInfo {
        name: name.to_string().into(),
        default,
        range: range.unwrap_or(ParamRange::UNBOUNDED),
        doc: docs::declaration(sources, span).into(),
        declared: docs::location(sources, span).into(),
        written: docs::written(sources, span).into(),
        owner: owner.to_string().into(),
    }
}

/// Every param the unit's forms read (its imports' included), in `Params` order; each owned by
/// the file that declares it.
pub fn params(prog: &Program) -> Vec<ParamInfo> {
    let src = &prog.sources;
    prog.params
        .iter()
        .map(|p| param(src, &p.name, p.default, p.range, p.span, &crate::source::module_name(src.path(p.span.file))))
        .collect()
}

/// A scheme's params, in declaration order.
pub fn scheme_params(prog: &Program, s: &SchemeIr) -> Vec<ParamInfo> {
    s.params.iter().map(|p| param(&prog.sources, &p.name, p.default, p.range, p.span, &s.name)).collect()
}

/// The coefs the unit's forms read.
pub fn coefs(prog: &Program) -> Vec<CoefInfo> {
    let src = &prog.sources;
    prog.coefs
        .iter()
        .map(|c| CoefInfo {
            name: c.name.clone().into(),
            rank: c.shape.rank(),
            doc: docs::declaration(src, c.span).into(),
            declared: docs::location(src, c.span).into(),
        })
        .collect()
}

/// The forms and functionals declared in the root file (not its imports).
pub fn slots(prog: &Program) -> Vec<SlotInfo> {
    let src = &prog.sources;
    prog.forms
        .iter()
        .filter(|f| f.span.file == prog.root)
        .map(|f| SlotInfo {
            name: f.name.clone().into(),
            fields: f.fields.len(),
            functional: f.test.is_none(),
            doc: docs::declaration(src, f.span).into(),
            declared: docs::location(src, f.span).into(),
        })
        .collect()
}
