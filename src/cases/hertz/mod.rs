//! Hertz validation: a cylinder (2D) and a ball (3D) pressed onto the rigid plane, and the
//! low-velocity impact of a ball, against Hertz's closed forms.

pub mod impact;
pub mod meshes;

use crate::cases::CaseError;
use crate::references::hertz::closed_form::Material;

/// Both cases' material (λ = μ = 20, the sphere's) and γ0 = 100 E (Nitsche with θ = 1 is unstable at
/// 10 E on the 3D meshes), over the files' defaults.
pub const OVERRIDES: &[(&str, f64)] = &[("E", 50.0), ("nu", 0.25), ("rho", 1.0), ("gamma0", 5000.0)];

/// The closed forms' material: the files' E, ν and ρ.
pub fn material(active: &crate::driver::ActiveForms) -> Result<Material, CaseError> {
    let get = |name: &str| {
        active.params.get(name).ok_or_else(|| {
            CaseError::Option(format!("Hertz's formulas need the material's `{name}`, which the files in use lack"))
        })
    };
    Ok(Material { young: get("E")?, poisson: get("nu")?, density: get("rho")? })
}
