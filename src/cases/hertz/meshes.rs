//! The graded meshes of the Hertz cases: Gmsh files made from assets/meshes/hertz_*.geo
//! (cells of one size in the contact zone, growing outside it; each level divides
//! every size by 2 in 2D, √2 in 3D) and compiled
//! into the binary, so that no run needs Gmsh.

use std::path::Path;

use crate::cases::CaseError;
use crate::runtime::mesh::{Mesh, gmsh};
use crate::runtime::problem::Constraints;

/// The radius of the bodies of the .geo files.
pub const RADIUS: f64 = 10.0;
/// The region bound to `Gamma_C`, and the symmetry planes x = 0 and y = 0.
pub const CONTACT: &str = "contact";
const SYMMETRY: [&str; 2] = ["symmetry_x", "symmetry_y"];

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

/// The ratio of the cell sizes of two successive levels.
pub fn level_ratio(dim: usize) -> f64 {
    if dim == 2 { 2.0 } else { std::f64::consts::SQRT_2 }
}

/// The number of built-in levels in `dim` dimensions.
pub fn levels(dim: usize) -> usize {
    if dim == 2 { CYLINDER.len() } else { BALL.len() }
}

/// The built-in mesh of `level`, or the file `path`; with a name for the summary.
pub fn load(dim: usize, level: usize, path: Option<&Path>) -> Result<(Mesh, String), CaseError> {
    let (mesh, name) = match path {
        Some(p) => (gmsh::read(p)?, p.display().to_string()),
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
    if mesh.dim() != dim {
        return Err(CaseError::Option(format!("{name} is a {}D mesh, the case is {dim}D", mesh.dim())));
    }
    mesh.region(CONTACT)?;
    for plane in &SYMMETRY[..dim - 1] {
        mesh.region(plane)?;
    }
    mesh.validate()?;
    Ok((mesh, name))
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
