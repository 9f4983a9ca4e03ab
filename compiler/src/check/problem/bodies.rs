//! A problem's bodies: distinct names, a source each (a group of the mesh file's cells, or a
//! known generator with its arguments), and their own `set` values and initial fields, checked
//! as the problem's are. Which cells a group holds, and that the bodies share out the mesh's
//! cells, is checked when the problem is bound to its mesh.

use super::{GENERATORS, Names, builtin_call, distinct, initial_fields, scalar};
use crate::check::types::Checker;
use crate::diagnostic::Diagnostic;
use crate::syntax::ast::{BodySource, MeshSource, Problem};

pub(super) fn check(c: &mut Checker, p: &Problem, constants: &Names, diags: &mut Vec<Diagnostic>) {
    distinct(p.bodies.iter().map(|b| &b.name), "body", diags);
    let file = p.mesh.iter().any(|m| matches!(m, MeshSource::File { .. }));
    for b in &p.bodies {
        match &b.source {
            BodySource::Generator(call) => builtin_call(c, call, GENERATORS, "mesh generator", constants, diags),
            BodySource::Group { span, .. } if !file => diags.push(
                Diagnostic::error(
                    "E0901",
                    format!("body `{}` is a group of cells, and the problem reads no mesh file", b.name.name),
                    *span,
                    "a physical group of a Gmsh file",
                )
                .with_help("add `mesh \"bodies.msh\"` (a Gmsh file whose physical surfaces or volumes are the bodies), or place the body with a generator: `body ball = disc(radius = 1, centre = [0, 2], h = 0.1)`"),
            ),
            BodySource::Group { .. } => {}
        }
        distinct(b.sets.iter().map(|d| &d.name), "`set` of a param", diags);
        for d in &b.sets {
            scalar(c, &d.value, constants, diags, false);
        }
        initial_fields(c, &b.initial, constants, false, diags);
    }
}
