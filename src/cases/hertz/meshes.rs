//! The graded meshes of the Hertz cases: Gmsh files made from assets/meshes/hertz_*.geo
//! (cells of one size in the contact zone, growing outside it; each level divides
//! every size by 2 in 2D, √2 in 3D) and compiled
//! into the binary, so that no run needs Gmsh.

use std::path::Path;

use crate::cases::CaseError;
use crate::runtime::mesh::{Mesh, gmsh};
use crate::runtime::problem::Constraints;

/// The radius of the bodies of the .geo files (checked on every mesh through its measure).
pub const RADIUS: f64 = 10.0;
/// The region bound to `Gamma_C`, and the symmetry planes x = 0 and y = 0.
pub const CONTACT: &str = "contact";
const SYMMETRY: [&str; 2] = ["symmetry_x", "symmetry_y"];

/// Level k of each set was made with `gmsh -d -setnumber level k` from the .geo file.
const CYLINDER: [&[u8]; 4] = [
    include_bytes!("../../../assets/meshes/hertz_cylinder_0.msh"),
    include_bytes!("../../../assets/meshes/hertz_cylinder_1.msh"),
    include_bytes!("../../../assets/meshes/hertz_cylinder_2.msh"),
    include_bytes!("../../../assets/meshes/hertz_cylinder_3.msh"),
];
const BALL: [&[u8]; 4] = [
    include_bytes!("../../../assets/meshes/hertz_ball_0.msh"),
    include_bytes!("../../../assets/meshes/hertz_ball_1.msh"),
    include_bytes!("../../../assets/meshes/hertz_ball_2.msh"),
    include_bytes!("../../../assets/meshes/hertz_ball_3.msh"),
];

/// How many copies of the model make the whole body: the half cylinder in 2D, the quarter
/// ball in 3D.
pub fn copies(dim: usize) -> f64 {
    if dim == 2 { 2.0 } else { 4.0 }
}

/// The measure of the whole body (its area in 2D).
pub fn body_measure(dim: usize) -> f64 {
    if dim == 2 { std::f64::consts::PI * RADIUS * RADIUS } else { 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3) }
}

/// The number of built-in levels in `dim` dimensions.
pub fn levels(dim: usize) -> usize {
    if dim == 2 { CYLINDER.len() } else { BALL.len() }
}

/// The built-in mesh of `level`, or the file `path`; with a name for the summary.
pub fn load(dim: usize, level: usize, path: Option<&Path>) -> Result<(Mesh, String), CaseError> {
    let (mesh, name) = match path {
        Some(p) => (crate::cases::read_mesh(p)?, p.display().to_string()),
        None => {
            let (set, stem) = match dim {
                2 => (&CYLINDER[..], "hertz_cylinder"),
                3 => (&BALL[..], "hertz_ball"),
                d => return Err(CaseError::Option(format!("--dim must be 2 or 3, not {d}"))),
            };
            let bytes = set.get(level).ok_or_else(|| {
                CaseError::Option(format!("--level must be below {} in {dim}D, not {level}", set.len()))
            })?;
            let name = format!("{stem}_{level}.msh");
            (gmsh::parse(bytes, &name)?, name)
        }
    };
    let mut mesh = mesh;
    if mesh.dim() != dim {
        return Err(CaseError::Option(format!("{name} is a {}D mesh, the case is {dim}D", mesh.dim())));
    }
    let missing = |e| CaseError::Option(format!("{name}: {e}"));
    for region in std::iter::once(&CONTACT).chain(&SYMMETRY[..dim - 1]) {
        mesh.region(region).map_err(missing)?;
    }
    mesh.validate()?;
    // The half (quarter) of a body of radius R: the closed forms and the load assume it.
    let exact = if dim == 2 {
        std::f64::consts::PI * RADIUS * RADIUS / 2.0
    } else {
        std::f64::consts::PI * RADIUS.powi(3) / 3.0
    };
    if (mesh.measure() / exact - 1.0).abs() > 0.01 {
        return Err(CaseError::Option(format!(
            "{name} measures {:.6}, not the {} of a body of radius {RADIUS} ({exact:.6})",
            mesh.measure(),
            if dim == 2 { "half" } else { "quarter" }
        )));
    }
    lower_half(&mut mesh, dim);
    Ok((mesh, name))
}

/// Keeps in the contact region only the facets facing the plane (outward normal pointing
/// down): Nitsche's −θ/γ σ_N(u) σ_N(v) term has no switch, and on the upper half, where the
/// cells are coarsest, it would only cost time and stability.
fn lower_half(mesh: &mut Mesh, dim: usize) {
    let Some(i) = mesh.regions.iter().position(|r| r.name == CONTACT) else { return };
    let facets = std::mem::take(&mut mesh.regions[i].facets);
    let kept = facets.into_iter().filter(|&f| mesh.facet_normal_and_centroid(f).0[dim - 1] < 0.0).collect();
    mesh.regions[i].facets = kept;
}

/// The normal displacement held at zero on the symmetry planes.
pub fn symmetry(mesh: &Mesh) -> Result<Constraints, CaseError> {
    let d = mesh.dim();
    let mut c = Constraints::none(mesh.num_nodes() * d);
    for (k, plane) in SYMMETRY[..d - 1].iter().enumerate() {
        c.fix_region(mesh, plane, &[k], |_| vec![0.0; d])?;
    }
    Ok(c)
}
