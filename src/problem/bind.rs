//! A problem bound to its params: the mesh (a Gmsh file or a generator) with the problem's
//! regions, the coefs the problem sets (obstacles' `g` and `nc` among them), the initial
//! fields, and the run's settings. Errors point at the problem file.

use std::path::Path;

use super::ProblemFile;
use super::expr::{At, Exprs, PointFn};
use crate::compiler::Diagnostic;
use crate::compiler::ir::lower::Val;
use crate::compiler::syntax::ast::{Condition, Expr, MeshSource, RegionSource};
use crate::driver::FilesInUse;
use crate::error::CaseError;
use crate::runtime::fem::kernel::Coef;
use crate::runtime::fem::mesh::{CellSize, Mesh};

/// The dimension of the problem's mesh: its generator's, or the file's (read here, and
/// returned for [`mesh`]). `params` are the problem's, for a file name that names them
/// (`"ball_{level}.msh"`).
pub fn dimension(
    pf: &ProblemFile,
    mesh_file: Option<&Path>,
    params: &[(String, f64)],
) -> Result<(usize, Option<ReadMesh>), CaseError> {
    let value = |name: &str| params.iter().find(|(n, _)| n == name).map(|(_, v)| *v);
    let primary = super::bodies::primary(pf.problem()).ok_or_else(|| no_mesh(pf))?;
    if mesh_file.is_some() && pf.problem().mesh.is_empty() {
        return Err(CaseError::Option(format!(
            "--mesh replaces a problem's `mesh` line, and problem `{}` has none: its bodies are placed by generators",
            pf.name()
        )));
    }
    match (&primary, mesh_file) {
        (MeshSource::Generator(call), Some(path)) => {
            let mesh = read(path)?;
            let d = mesh.dim();
            let g = crate::compiler::check::problem::GENERATORS.iter().find(|g| g.name == call.name.name);
            match g {
                Some(g) if g.dim != d => Err(CaseError::Option(format!(
                    "problem `{}` is {}D (its mesh: {}): {} is a {d}D mesh",
                    pf.name(),
                    g.dim,
                    g.name,
                    path.display()
                ))),
                _ => Ok((d, Some(ReadMesh { path: path.to_path_buf(), mesh }))),
            }
        }
        (_, Some(path)) => {
            let mesh = read(path)?;
            Ok((mesh.dim(), Some(ReadMesh { path: path.to_path_buf(), mesh })))
        }
        (MeshSource::Generator(call), None) => {
            let g = crate::compiler::check::problem::GENERATORS.iter().find(|g| g.name == call.name.name);
            Ok((g.map_or(0, |g| g.dim), None))
        }
        (MeshSource::File { path, span }, None) => {
            let path = fill(pf, path, *span, &value)?;
            let mesh = read_own(pf, &path, *span)?;
            Ok((mesh.dim(), Some(ReadMesh { path: path.into(), mesh })))
        }
    }
}

/// A problem with no cells (the checker refuses it first).
fn no_mesh(pf: &ProblemFile) -> CaseError {
    CaseError::Option(format!("problem `{}` has no mesh", pf.name()))
}

/// A mesh file [`dimension`] read, handed to [`mesh`] so that the file is read (and its
/// warnings shown) once: `path` as given (a problem's own file: relative to it).
pub struct ReadMesh {
    path: std::path::PathBuf,
    mesh: Mesh,
}

impl ReadMesh {
    /// The mesh, if it was read from `path`.
    fn of(read: &mut Option<ReadMesh>, path: &Path) -> Option<Mesh> {
        read.take_if(|r| r.path == path).map(|r| r.mesh)
    }
}

fn read(path: &Path) -> Result<Mesh, CaseError> {
    Ok(read_mesh(path)?)
}

/// Reads a Gmsh file, showing on stderr what the reader skipped (also logged as a warning).
fn read_mesh(path: &Path) -> Result<Mesh, crate::runtime::fem::mesh::MeshError> {
    let mesh = crate::runtime::fem::mesh::gmsh::read(path)?;
    for w in &mesh.warnings {
        eprintln!("warning: {w}");
    }
    Ok(mesh)
}

/// The problem's own mesh file, its errors located at the `mesh` line.
fn read_own(pf: &ProblemFile, path: &str, span: crate::compiler::Span) -> Result<Mesh, CaseError> {
    let full = pf.dir.join(path);
    read_mesh(&full).map_err(|e| {
        pf.render(Diagnostic::error("E0101", format!("cannot read the mesh {}", full.display()), span, e.to_string()))
    })
}

/// A mesh file's name with each `{NAME}` replaced by the value of the param (or constant `let`)
/// NAME: `"hertz_ball_{level}.msh"` is `"hertz_ball_2.msh"` at level = 2.
fn fill(
    pf: &ProblemFile,
    path: &str,
    span: crate::compiler::Span,
    value: &dyn Fn(&str) -> Option<f64>,
) -> Result<String, CaseError> {
    let mut out = String::new();
    let mut rest = path;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let Some(close) = rest[open..].find('}') else { break };
        let name = &rest[open + 1..open + close];
        let v = value(name).ok_or_else(|| {
            pf.render(Diagnostic::error(
                "E0101",
                format!("`{{{name}}}` in the mesh's file name is not a param of the problem"),
                span,
                "in this file name",
            ))
        })?;
        out.push_str(&if v.fract() == 0.0 && v.abs() < 1e15 { format!("{}", v as i64) } else { format!("{v}") });
        rest = &rest[open + close + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The mesh: `mesh_file` (`--mesh`) or the problem's, with the problem's regions, validated;
/// `read_already` if it is that file ([`dimension`]'s read). The label says what it is in
/// summaries.
pub fn mesh(
    pf: &ProblemFile,
    ex: &mut Exprs,
    mesh_file: Option<&Path>,
    cell_size: CellSize,
    mut read_already: Option<ReadMesh>,
) -> Result<(Mesh, String), CaseError> {
    let p = pf.problem();
    let name = pf.name();
    let d = ex.dim();
    let primary = super::bodies::primary(p).ok_or_else(|| no_mesh(pf))?;
    let (mut mesh, mut label) = match (&primary, mesh_file) {
        (_, Some(path)) => {
            let mesh = match ReadMesh::of(&mut read_already, path) {
                Some(mesh) => mesh,
                None => read(path)?,
            };
            (mesh, path.display().to_string())
        }
        (MeshSource::File { path, span }, None) => {
            let path = fill(pf, path, *span, &|name| ex.constant(name))?;
            let mesh = match ReadMesh::of(&mut read_already, Path::new(&path)) {
                Some(mesh) => mesh,
                None => read_own(pf, &path, *span)?,
            };
            (mesh, pf.dir.join(&path).display().to_string())
        }
        (MeshSource::Generator(call), None) => super::generate::generate(pf, ex, call)?,
    };
    if mesh_file.is_some() || matches!(primary, MeshSource::File { .. }) {
        crate::resources::check(name, (mesh.num_nodes() * mesh.dim()) as f64, mesh.dim(), None)?;
    }
    let bodies = super::bodies::place(pf, ex, &mut mesh, &mut label)?;
    if mesh.dim() != d {
        return Err(CaseError::Option(format!("problem `{name}` is {d}D: {label} is {}D", mesh.dim())));
    }
    // The mesh's own groups, for messages.
    let groups: Vec<String> = mesh.regions.iter().map(|g| g.name.clone()).collect();
    for r in &p.regions {
        let mut found = false;
        for source in &r.sources {
            // A group the mesh has is the region, even empty (an error, not a fallback).
            if let Some(facets) = facets_of(pf, ex, &mesh, source, &r.name.name, &label)? {
                let facets = match &r.body {
                    Some(body) => super::bodies::cut(facets, &body.name, &bodies, mesh.num_cells()),
                    None => facets,
                };
                found = !facets.is_empty();
                if found || matches!(source, RegionSource::Group { .. }) {
                    mesh.regions.retain(|x| x.name != r.name.name);
                    mesh.regions.push(crate::runtime::fem::mesh::Region { name: r.name.name.clone(), facets });
                    found = true;
                }
            }
            if found {
                break;
            }
        }
        if !found {
            let groups: Vec<&str> = groups.iter().map(String::as_str).collect();
            let mut d = Diagnostic::error(
                "E0101",
                format!("region `{}` names no facet of {label}", r.name.name),
                r.span,
                "empty region",
            );
            if let Some(RegionSource::Group { name: g, .. }) = r.sources.first()
                && let Some(close) = crate::compiler::check::suggest_name(g, groups.iter().copied())
            {
                d = d.with_help(format!("did you mean group \"{close}\"?"));
            }
            let list = if groups.is_empty() { "none".to_string() } else { groups.join(", ") };
            return Err(pf.render(d.with_note(format!("the mesh's facet groups: {list}"))));
        }
    }
    mesh.set_cell_size(cell_size);
    mesh.validate()?;
    for r in &p.regions {
        mesh.region(&r.name.name)?;
    }
    if !bodies.is_empty() {
        mesh.set_bodies(bodies);
    }
    Ok((mesh, label))
}

/// The facets of a region's source, in order: none when it is a group the mesh does not have
/// (the next source is tried); an error for a group the mesh has with no facet there.
fn facets_of(
    pf: &ProblemFile,
    ex: &mut Exprs,
    mesh: &Mesh,
    source: &RegionSource,
    region: &str,
    label: &str,
) -> Result<Option<Vec<crate::runtime::fem::mesh::Facet>>, CaseError> {
    let keep = |ex: &mut Exprs, facets: Vec<crate::runtime::fem::mesh::Facet>, condition: &Option<Condition>| {
        let Some(c) = condition else { return Ok(facets) };
        let test = predicate(pf, ex, c)?;
        Ok::<_, CaseError>(
            facets
                .into_iter()
                .filter(|&f| {
                    let (n, x) = mesh.facet_normal_and_centroid(f);
                    test(&n, &x)
                })
                .collect(),
        )
    };
    Ok(Some(match source {
        RegionSource::Group { name: group, condition, span } => {
            let Some(g) = mesh.regions.iter().find(|g| g.name == *group) else { return Ok(None) };
            let facets = keep(ex, g.facets.clone(), condition)?;
            if facets.is_empty() {
                return Err(pf.render(Diagnostic::error(
                    "E0101",
                    format!("group \"{group}\" of {label} has no facets"),
                    *span,
                    format!("region `{region}` would be empty"),
                )));
            }
            facets
        }
        RegionSource::Boundary { condition, .. } => keep(ex, mesh.boundary_facets(), condition)?,
        // Earlier regions are the mesh's by now (the checker refused later ones).
        RegionSource::Region(id) => {
            mesh.regions.iter().find(|g| g.name == id.name).map_or_else(Vec::new, |g| g.facets.clone())
        }
        RegionSource::Union(parts, _) => {
            let mut all: Vec<crate::runtime::fem::mesh::Facet> = Vec::new();
            for part in parts {
                for f in facets_of(pf, ex, mesh, part, region, label)?.unwrap_or_default() {
                    if !all.contains(&f) {
                        all.push(f);
                    }
                }
            }
            all
        }
    }))
}

/// A facet test from a condition on the outward normal `n` and the centroid `x`.
fn predicate(
    pf: &ProblemFile,
    ex: &mut Exprs,
    condition: &Condition,
) -> Result<impl Fn(&[f64], &[f64]) -> bool, CaseError> {
    let mut tests = Vec::new();
    for c in condition.comparisons() {
        let lhs = ex.lower(&c.lhs, &[]).map_err(|e| pf.render(*e))?;
        let rhs = ex.lower(&c.rhs, &[]).map_err(|e| pf.render(*e))?;
        let both = Val { shape: lhs.shape, c: vec![lhs.c[0].clone(), rhs.c[0].clone()] };
        tests.push((ex.function(&both, &c.lhs).map_err(|e| pf.render(*e))?, c.op));
    }
    let condition = condition.clone();
    let work = std::cell::RefCell::new((Vec::new(), [0.0; 2]));
    Ok(move |n: &[f64], x: &[f64]| {
        let (scratch, out) = &mut *work.borrow_mut();
        let mut holds = tests.iter().map(|(f, op)| {
            f.eval(&At { x, n, ..At::default() }, scratch, out);
            op.holds(out[0], out[1])
        });
        condition.holds(&mut holds)
    })
}

/// The coefs the problem sets, by name: its `coef` lines, then its obstacles' `g` and `nc`.
pub fn coefs(pf: &ProblemFile, ex: &mut Exprs) -> Result<Vec<(String, PointFn)>, CaseError> {
    let p = pf.problem();
    let mut out = Vec::new();
    for c in &p.coefs {
        let v = ex.lower(&c.value, &[]).map_err(|e| pf.render(*e))?;
        out.push((c.name.name.clone(), ex.coef_function(&v, &c.value).map_err(|e| pf.render(*e))?));
    }
    for (g, nc, e) in obstacle_vals(pf, ex)? {
        out.push(("g".into(), ex.coef_function(&g, e).map_err(|e| pf.render(*e))?));
        out.push(("nc".into(), ex.coef_function(&nc, e).map_err(|e| pf.render(*e))?));
    }
    for (k, b) in p.neumann.iter().enumerate() {
        let v = ex.lower(&b.value, &[]).map_err(|e| pf.render(*e))?;
        out.push((super::neumann::coef(k), ex.function(&v, &b.value).map_err(|e| pf.render(*e))?));
    }
    Ok(out)
}

/// The values of every coef the problem sets, for pointwise observables: (name, value).
pub fn coef_vals(pf: &ProblemFile, ex: &mut Exprs) -> Result<Vec<(String, Val)>, CaseError> {
    let p = pf.problem();
    let mut out = Vec::new();
    for c in &p.coefs {
        out.push((c.name.name.clone(), ex.lower(&c.value, &[]).map_err(|e| pf.render(*e))?));
    }
    for (g, nc, _) in obstacle_vals(pf, ex)? {
        out.push(("g".into(), g));
        out.push(("nc".into(), nc));
    }
    Ok(out)
}

/// Each obstacle's gap and normal as values, with the expression to blame.
fn obstacle_vals<'p>(pf: &'p ProblemFile, ex: &mut Exprs) -> Result<Vec<(Val, Val, &'p Expr)>, CaseError> {
    let p = pf.problem();
    if p.obstacles.len() > 1 {
        return Err(pf.render(Diagnostic::error(
            "E0102",
            "one obstacle per problem for now",
            p.obstacles[1].span,
            "a second obstacle",
        )));
    }
    let mut out = Vec::new();
    for o in &p.obstacles {
        use crate::compiler::check::problem::ObstacleShape;
        let shape = crate::compiler::check::problem::obstacle(&o.shape).map_err(|why| {
            pf.render(Diagnostic::error("E0101", why, o.shape.span, "not an obstacle this run knows"))
        })?;
        let lower = |ex: &mut Exprs, e: &'p Expr| -> Result<(Val, &'p Expr), CaseError> {
            Ok((ex.lower(e, &[]).map_err(|d| pf.render(*d))?, e))
        };
        let x = ex.lower(&x_expr(o.shape.span), &[]).map_err(|e| pf.render(*e))?;
        let (centre, radius, axis) = match shape {
            ObstacleShape::Plane { point, normal } => {
                let ((point, e), (normal, _)) = (lower(ex, point)?, lower(ex, normal)?);
                let g = &mut ex.low.g;
                // gap = (x − point)·normal, nc = −normal.
                let mut gap = g.zero();
                for k in 0..x.c.len() {
                    let dx = g.sub(x.c[k].v, point.c[k].v);
                    let term = g.mul(dx, normal.c[k].v);
                    gap = g.add(gap, term);
                }
                let nc = normal.c.iter().map(|j| crate::compiler::ir::lower::Jet { v: g.neg(j.v), g: None }).collect();
                out.push((scalar(gap), Val { shape: normal.shape, c: nc }, e));
                continue;
            }
            ObstacleShape::Sphere { centre, radius } => (centre, radius, None),
            ObstacleShape::Cylinder { point, radius, axis } => {
                if axis.is_none() && x.c.len() == 3 {
                    return Err(pf.render(Diagnostic::error(
                        "E0201",
                        "a cylinder in 3D needs its `axis`",
                        o.shape.span,
                        "no `axis = [...]`",
                    )));
                }
                (point, radius, axis)
            }
        };
        // A sphere: gap = |x − centre| − radius, nc = (centre − x)/|x − centre|; a
        // cylinder: the same with the part of x − point across the axis.
        let ((centre, e), (radius, _)) = (lower(ex, centre)?, lower(ex, radius)?);
        let axis = match axis {
            Some(a) if x.c.len() == 3 => {
                let axis = ex.lower(a, &[]).map_err(|d| pf.render(*d))?;
                // A constant axis must have a direction (one that moves is the user's).
                let constant: Option<Vec<f64>> = axis.c.iter().map(|j| ex.low.g.as_const(j.v)).collect();
                if constant.is_some_and(|v| v.iter().all(|x| *x == 0.0)) {
                    return Err(pf.render(Diagnostic::error(
                        "E0301",
                        "a cylinder's axis is not zero",
                        a.span,
                        "no direction",
                    )));
                }
                Some(axis)
            }
            Some(a) => {
                return Err(pf.render(
                    Diagnostic::error("E0302", "wrong dimension", a.span, "a 2D cylinder has no axis")
                        .with_help("in 2D a cylinder is its section, the disc of `radius` about `point`"),
                ));
            }
            None => None,
        };
        let g = &mut ex.low.g;
        let mut diff: Vec<_> = (0..x.c.len()).map(|k| g.sub(x.c[k].v, centre.c[k].v)).collect();
        if let Some(axis) = axis {
            // d − (d·a) a / (a·a)
            let (mut along, mut norm2) = (g.zero(), g.zero());
            for k in 0..diff.len() {
                let p = g.mul(diff[k], axis.c[k].v);
                along = g.add(along, p);
                let q = g.mul(axis.c[k].v, axis.c[k].v);
                norm2 = g.add(norm2, q);
            }
            let s = g.div(along, norm2);
            for k in 0..diff.len() {
                let p = g.mul(s, axis.c[k].v);
                diff[k] = g.sub(diff[k], p);
            }
        }
        let mut r2 = g.zero();
        for &dk in &diff {
            let sq = g.mul(dk, dk);
            r2 = g.add(r2, sq);
        }
        let dist = g.sqrt(r2);
        let gap = g.sub(dist, radius.c[0].v);
        let nc = diff
            .iter()
            .map(|&dk| {
                let q = g.div(dk, dist);
                crate::compiler::ir::lower::Jet { v: g.neg(q), g: None }
            })
            .collect();
        out.push((scalar(gap), Val { shape: centre.shape, c: nc }, e));
    }
    Ok(out)
}

fn scalar(v: crate::compiler::ir::graph::NodeId) -> Val {
    Val { shape: crate::compiler::syntax::ast::Shape::Scalar, c: vec![crate::compiler::ir::lower::Jet { v, g: None }] }
}

/// The expression `x`, at `span`.
fn x_expr(span: crate::compiler::Span) -> Expr {
    use crate::compiler::syntax::ast::{ExprKind, Ident};
    Expr { kind: ExprKind::Name(Ident { name: "x".into(), span }), span }
}

/// Settings as the problem gives them (`run dt = ...`, `quadrature cell = ...`), by name.
pub fn settings(
    pf: &ProblemFile,
    ex: &mut Exprs,
    list: &[crate::compiler::syntax::ast::Defined],
) -> Result<Vec<(String, f64)>, CaseError> {
    list.iter().map(|d| Ok((d.name.name.clone(), ex.scalar(&d.value).map_err(|e| pf.render(*e))?))).collect()
}

/// An initial field at the mesh's nodes at time `t0` (zeros if the problem gives none), with
/// no negative zeros; a body's own `initial` line holds at its nodes.
pub fn initial(pf: &ProblemFile, ex: &mut Exprs, mesh: &Mesh, field: &str, t0: f64) -> Result<Vec<f64>, CaseError> {
    let d = mesh.dim();
    let mut values = vec![0.0; mesh.num_nodes() * d];
    let p = pf.problem();
    let of = |list: &[crate::compiler::syntax::ast::Defined]| list.iter().find(|i| i.name.name == field).cloned();
    let mut defs: Vec<(Option<Vec<bool>>, Expr)> = Vec::new();
    if let Some(def) = of(&p.initial) {
        // `settled(GUESS)`: the guess here; the run settles it (`settled`).
        let value = match crate::compiler::check::problem::settled_guess(&def.value) {
            Some([guess]) => guess.clone(),
            _ => def.value,
        };
        defs.push((None, value));
    }
    for body in &p.bodies {
        if let (Some(def), Some(nodes)) = (of(&body.initial), mesh.body_nodes(&body.name.name)) {
            defs.push((Some(nodes), def.value));
        }
    }
    let mut scratch = Vec::new();
    for (nodes, value) in defs {
        let v = ex.lower(&value, &[]).map_err(|e| pf.render(*e))?;
        let f = ex.function(&v, &value).map_err(|e| pf.render(*e))?;
        for (i, out) in values.chunks_mut(d).enumerate().filter(|(i, _)| nodes.as_ref().is_none_or(|n| n[*i])) {
            f.eval(&At { x: mesh.node(i), t: t0, ..At::default() }, &mut scratch, out);
            out.iter_mut().for_each(|x| *x += 0.0);
        }
    }
    Ok(values)
}

/// Whether the problem's initial displacement is `settled(GUESS)`: in static equilibrium, sought
/// from the guess [`initial`] gives.
pub fn settled(pf: &ProblemFile) -> bool {
    pf.problem()
        .initial
        .iter()
        .any(|i| i.name.name == "u" && crate::compiler::check::problem::settled_guess(&i.value).is_some())
}

/// What a coef lookup by name gives the forms.
/// The region the contact laws integrate over.
pub const CONTACT: &str = "Gamma_C";

/// A problem without contact: no region `Gamma_C` and no obstacle. The contact law of the run
/// is bound on an empty region, and the coefs only it reads are zero.
pub fn contact_free(pf: &ProblemFile) -> bool {
    let p = pf.problem();
    p.obstacles.is_empty() && !p.regions.iter().any(|r| r.name.name == CONTACT)
}

pub fn coef_lookup(coefs: &[(String, PointFn)]) -> impl Fn(&str) -> Option<Coef> + '_ {
    move |name| coefs.iter().find(|(n, _)| n == name).map(|(_, f)| f.clone().coef())
}

/// Every coef the files in use read must be set by the problem (a `coef` line, or an
/// obstacle's `g` and `nc`): a located error before anything runs. A coef the problem sets that
/// no file reads is a warning (a misspelt name, or a file left out).
pub fn unset_coefs(pf: &ProblemFile, in_use: &FilesInUse) -> Result<(), CaseError> {
    use crate::compiler::Diagnostic;
    let p = pf.problem();
    let read: Vec<String> = in_use.forms.units.iter().flat_map(|u| u.coefs()).map(|(n, _)| n).collect();
    for c in &p.coefs {
        if !read.contains(&c.name.name) {
            let files: Vec<&str> = in_use.forms.units.iter().map(|u| u.file()).collect();
            let w = crate::compiler::check::problem::unread_coef(&c.name, &files);
            eprintln!("{}", crate::compiler::render_all(&[w], &pf.program.unit.sources).trim_end());
        }
    }
    let mut set: Vec<&str> = p.coefs.iter().map(|c| c.name.name.as_str()).collect();
    if !p.obstacles.is_empty() {
        set.extend(["g", "nc"]);
    }
    let loads: Vec<String> = (0..p.neumann.len()).map(super::neumann::coef).collect();
    set.extend(loads.iter().map(String::as_str));
    let free = contact_free(pf);
    let contact = in_use.forms.contact_units();
    for (i, unit) in in_use.forms.units.iter().enumerate() {
        if free && contact.contains(&i) {
            continue; // integrates over no facet: its coefs are zero
        }
        for (c, _) in unit.coefs() {
            if !set.contains(&c.as_str()) {
                let mut d = Diagnostic::error(
                    "E0101",
                    format!("problem `{}` does not set coef `{c}`, which {} reads", pf.name(), unit.file()),
                    p.name.span,
                    "no `coef` line for it",
                )
                .with_help(format!("add `coef {c} = EXPR` (an expression of x and t) to the problem"));
                if let Some(close) = crate::compiler::check::suggest_name(&c, set.iter().copied()) {
                    d = d.with_note(format!("the problem sets `{close}`: a misspelling?"));
                }
                return Err(pf.render(d));
            }
        }
    }
    Ok(())
}

/// Each coef the problem sets has the components the files in use read it with.
pub fn coef_shapes(
    pf: &ProblemFile,
    in_use: &FilesInUse,
    coefs: &[(String, PointFn)],
    d: usize,
) -> Result<(), CaseError> {
    use crate::compiler::Diagnostic;
    for unit in &in_use.forms.units {
        for (name, rank) in unit.coefs() {
            let Some((_, f)) = coefs.iter().find(|(n, _)| *n == name) else { continue };
            let need = d.pow(rank);
            if f.len() != need {
                let at = pf
                    .problem()
                    .coefs
                    .iter()
                    .find(|c| c.name.name == name)
                    .map_or(pf.problem().name.span, |c| c.value.span);
                let shape = ["a scalar", "a vector", "a tensor"][rank.min(2) as usize];
                return Err(pf.render(Diagnostic::error(
                    "E0301",
                    "shape mismatch",
                    at,
                    format!("{} reads `{name}` as {shape} ({need} components in {d}D), not {}", unit.file(), f.len()),
                )));
            }
        }
    }
    Ok(())
}
