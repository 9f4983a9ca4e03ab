//! The built-in generators' meshes: their arguments evaluated (constants of the problem's
//! params), checked (whole numbers of cells, positive sizes) and the memory the mesh needs
//! checked before it is built.

use super::ProblemFile;
use super::expr::Exprs;
use crate::compiler::Diagnostic;
use crate::compiler::syntax::ast::{Expr, NamedCall};
use crate::error::CaseError;
use crate::runtime::fem::mesh::Mesh;

/// A built-in generator's mesh, after a check that it fits in memory; and its label, the
/// arguments' values (`built-in disc(radius = 10, h = 1, centre = [0.0, 12.0])`).
pub(super) fn generate(pf: &ProblemFile, ex: &mut Exprs, call: &NamedCall) -> Result<(Mesh, String), CaseError> {
    use crate::compiler::check::problem::Generator;
    use crate::runtime::fem::mesh::{ball::ball, disc::disc, structured};
    let generator = crate::compiler::check::problem::generator(call)
        .map_err(|why| pf.render(Diagnostic::error("E0101", why, call.span, "not a generator this run knows")))?;
    let mut values = Vec::new();
    // A generator's numbers are constants: an expression of x or t is an error here.
    let mut get = |ex: &mut Exprs, name: &str, e: Option<&Expr>, default: f64| -> Result<f64, CaseError> {
        let v = match e {
            Some(e) => ex.scalar(e).map_err(|d| pf.render(*d))?,
            None => default,
        };
        values.push(format!("{name} = {v}"));
        Ok(v)
    };
    let count = |name: &str, v: f64| -> Result<usize, CaseError> {
        if (1.0..=1e7).contains(&v) && v.fract() == 0.0 {
            Ok(v as usize)
        } else {
            Err(CaseError::Option(format!(
                "{}: `{name}` must be a whole number of cells in [1, 10⁷], not {v}",
                pf.file
            )))
        }
    };
    let positive = |name: &str, v: f64| -> Result<f64, CaseError> {
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(CaseError::Option(format!("{}: `{name}` must be positive, not {v}", pf.file)))
        }
    };
    let vector = |ex: &mut Exprs, e: &Expr| ex.vector(e).map_err(|d| pf.render(*d));
    let origin = |ex: &mut Exprs, e: Option<&Expr>, dim: usize| e.map_or(Ok(vec![0.0; dim]), |e| vector(ex, e));
    let name = pf.name().to_string();
    let mesh = match generator {
        Generator::Interval { length, cells, start } => {
            let (length, cells) = (get(ex, "length", Some(length), 0.0)?, get(ex, "cells", Some(cells), 0.0)?);
            let start = get(ex, "start", start, 0.0)?;
            let cells = count("cells", cells)?;
            crate::resources::check(&name, cells as f64 + 1.0, 1, None)?;
            structured::interval(cells, start, start + positive("length", length)?)
        }
        Generator::Disc { radius, centre, h } | Generator::Ball { radius, centre, h } => {
            let radius = positive("radius", get(ex, "radius", Some(radius), 0.0)?)?;
            let h = positive("h", get(ex, "h", Some(h), 0.0)?)?;
            let centre = vector(ex, centre)?;
            values.push(format!("centre = {centre:?}"));
            if matches!(generator, Generator::Disc { .. }) {
                // P2 nodes: 3m² vertices on m rings.
                let dofs = 2.0 * 4.0 * 3.0 * (radius / h).ceil().powi(2);
                crate::resources::check(&name, dofs, 2, Some(h))?;
                disc(radius, [centre[0], centre[1]], h)
            } else {
                // P2 nodes: the (2n+1)³ lattice.
                let dofs = 3.0 * (4.0 * (radius / h).round() + 1.0).powi(3);
                crate::resources::check(&name, dofs, 3, Some(h))?;
                ball(radius, [centre[0], centre[1], centre[2]], h)
            }
        }
        Generator::Rectangle { width, height, nx, ny, degree, origin: at } => {
            let w = positive("width", get(ex, "width", Some(width), 0.0)?)?;
            let h = positive("height", get(ex, "height", Some(height), 0.0)?)?;
            let (nx, ny) = (count("nx", get(ex, "nx", Some(nx), 0.0)?)?, count("ny", get(ex, "ny", Some(ny), 0.0)?)?);
            let degree = if get(ex, "degree", degree, 1.0)? == 2.0 { 2 } else { 1 };
            crate::resources::check(&name, 2.0 * ((degree * nx + 1) * (degree * ny + 1)) as f64, 2, None)?;
            let o = origin(ex, at, 2)?;
            values.push(format!("origin = {o:?}"));
            structured::rectangle(
                nx,
                ny,
                [o[0], o[0] + w],
                [o[1], o[1] + h],
                structured::Diagonal::Right,
                degree as u32,
            )
        }
        Generator::Box { size, nx, ny, nz, degree, origin: at } => {
            let size = vector(ex, size)?;
            let n = [
                count("nx", get(ex, "nx", Some(nx), 0.0)?)?,
                count("ny", get(ex, "ny", Some(ny), 0.0)?)?,
                count("nz", get(ex, "nz", Some(nz), 0.0)?)?,
            ];
            let degree = if get(ex, "degree", degree, 1.0)? == 2.0 { 2 } else { 1 };
            let nodes: usize = n.iter().map(|k| degree * k + 1).product();
            crate::resources::check(&name, 3.0 * nodes as f64, 3, None)?;
            let o = origin(ex, at, 3)?;
            values.push(format!("origin = {o:?}"));
            structured::cuboid(n, [o[0], o[0] + size[0]], [o[1], o[1] + size[1]], [o[2], o[2] + size[2]], degree as u32)
        }
    };
    Ok((mesh, format!("built-in {}({})", call.name.name, values.join(", "))))
}
