//! Binds the compiled form library to the names schemes use (`mass`, `stiffness`, `load`,
//! `contact`, `hybrid_contact`), for a material, a contact law and case data.

use super::CaseError;
use super::static_block::ContactMethod;
use crate::forms::schemes::hybrid;
use crate::forms::{nitsche, penalty};
use crate::runtime::assembly::{Assembler, Functional, Kernel, Quadrature};
use crate::runtime::kernel::{Coef, ParamError};
use crate::runtime::linalg::Structure;
use crate::runtime::mesh::Facet;
use crate::runtime::scheme::{self, BoundForm};

/// A form bound to the name a scheme uses for it.
pub type Slot<'m> = (&'static str, Box<dyn BoundForm + 'm>);

#[derive(Clone, Copy, Debug)]
pub struct Material {
    pub young: f64,
    pub poisson: f64,
    pub density: f64,
}

#[derive(Clone, Copy, Debug)]
pub struct Contact<'m> {
    pub method: ContactMethod,
    pub theta: f64,
    pub gamma0: f64,
    /// Mesh facets of Γ_C.
    pub facets: &'m [Facet],
}

/// Body force, gap and obstacle normal (fresh copies for each form module).
pub type CaseData<'a> = &'a dyn Fn() -> (Coef, Coef, Coef);

fn bound<'m, K: Kernel + 'm>(
    kernel: K,
    quadrature: Quadrature,
    facets: Option<&'m [Facet]>,
) -> Box<dyn BoundForm + 'm> {
    let regions = facets.map(|f| vec![("Gamma_C".to_string(), f)]).unwrap_or_default();
    Box::new(scheme::Bound { kernel, quadrature, regions })
}

fn bad(e: ParamError) -> CaseError {
    CaseError::Option(e.to_string())
}

/// The contact term of the augmented energy (E_Θ − E for Nitsche, E_pen − E for penalty) at a
/// displacement.
pub type ContactEnergy<'m> = Box<dyn Fn(&Assembler, &[f64]) -> f64 + 'm>;

fn energy<'m, K: Functional + 'm>(kernel: K, quadrature: Quadrature, facets: &'m [Facet]) -> ContactEnergy<'m> {
    Box::new(move |asm: &Assembler, u: &[f64]| asm.facet_value(&kernel, "Gamma_C", facets, quadrature, &[u], 0.0))
}

/// What a case needs from the form library.
pub struct Bound<'m> {
    pub forms: Vec<Slot<'m>>,
    /// Cholesky (θ = 1 and penalty: symmetric) or LU for the stage Jacobians.
    pub structure: Structure,
    pub contact_energy: ContactEnergy<'m>,
    /// Another instance of the `contact` form, for measurements (resultant, active points).
    pub contact_probe: Box<dyn BoundForm + 'm>,
    /// Cell averages of the von Mises stress (plane strain) at a displacement.
    pub von_mises: CellField<'m>,
}

/// Per-cell values of a displacement.
pub type CellField<'m> = Box<dyn Fn(&Assembler, &[f64]) -> Vec<f64> + 'm>;

/// Cell averages of the library's plane-strain von Mises stress for a material.
fn von_mises<'m>(material: Material, data: CaseData<'_>, quadrature: Quadrature) -> Result<CellField<'m>, CaseError> {
    let mut p = nitsche::Params::default();
    for (name, v) in [("E", material.young), ("nu", material.poisson), ("rho", material.density)] {
        p.set(name, v).map_err(bad)?;
    }
    let (f, g, nc) = data();
    let c = nitsche::Coefficients { f, g, nc };
    let (vm, measure) = (nitsche::VonMises::new(&p, &c), nitsche::Measure::new(&p, &c));
    Ok(Box::new(move |asm: &Assembler, u: &[f64]| {
        let area = asm.cell_values(&measure, quadrature, &[], 0.0);
        asm.cell_values(&vm, quadrature, &[u], 0.0).iter().zip(&area).map(|(v, a)| v / a).collect()
    }))
}

/// Binds the library for a material and a contact law.
pub fn bind<'m>(
    material: Material,
    contact: Contact<'m>,
    data: CaseData<'_>,
    quadrature: Quadrature,
) -> Result<Bound<'m>, CaseError> {
    let q = quadrature;
    let facets = Some(contact.facets);
    let set = |p: f64, name: &str| (name.to_string(), p);
    let common = [
        set(material.young, "E"),
        set(material.poisson, "nu"),
        set(material.density, "rho"),
        set(contact.gamma0, "gamma0"),
    ];
    match contact.method {
        ContactMethod::Nitsche => {
            let mut p = nitsche::Params::default();
            for (name, v) in common.iter().chain([&set(contact.theta, "theta")]) {
                p.set(name, *v).map_err(bad)?;
            }
            let (f, g, nc) = data();
            let c = nitsche::Coefficients { f, g, nc };
            let mut hp = hybrid::Params::default();
            for (name, v) in common.iter().chain([&set(contact.theta, "theta")]) {
                hp.set(name, *v).map_err(bad)?;
            }
            let (f, g, nc) = data();
            let hc = hybrid::Coefficients { f, g, nc };
            let forms: Vec<Slot<'m>> = vec![
                ("mass", bound(nitsche::Mass::new(&p, &c), q, None)),
                ("stiffness", bound(nitsche::Stiffness::new(&p, &c), q, None)),
                ("load", bound(nitsche::Load::new(&p, &c), q, None)),
                ("contact", bound(nitsche::Contact::new(&p, &c), q, facets)),
                ("hybrid_contact", bound(hybrid::HybridContact::new(&hp, &hc), q, facets)),
            ];
            Ok(Bound {
                forms,
                structure: if contact.theta == 1.0 { Structure::SymmetricPositiveDefinite } else { Structure::General },
                contact_energy: energy(nitsche::ContactEnergy::new(&p, &c), q, contact.facets),
                contact_probe: bound(nitsche::Contact::new(&p, &c), q, facets),
                von_mises: von_mises(material, data, q)?,
            })
        }
        ContactMethod::Penalty => {
            let mut p = penalty::Params::default();
            for (name, v) in &common {
                p.set(name, *v).map_err(bad)?;
            }
            let (f, g, nc) = data();
            let c = penalty::Coefficients { f, g, nc };
            let mut hp = hybrid::Params::default();
            for (name, v) in &common {
                hp.set(name, *v).map_err(bad)?;
            }
            let (f, g, nc) = data();
            let hc = hybrid::Coefficients { f, g, nc };
            let forms: Vec<Slot<'m>> = vec![
                ("mass", bound(penalty::Mass::new(&p, &c), q, None)),
                ("stiffness", bound(penalty::Stiffness::new(&p, &c), q, None)),
                ("load", bound(penalty::Load::new(&p, &c), q, None)),
                ("contact", bound(penalty::Contact::new(&p, &c), q, facets)),
                ("hybrid_contact", bound(hybrid::HybridPenalty::new(&hp, &hc), q, facets)),
            ];
            Ok(Bound {
                forms,
                structure: Structure::SymmetricPositiveDefinite,
                contact_energy: energy(penalty::ContactEnergy::new(&p, &c), q, contact.facets),
                contact_probe: bound(penalty::Contact::new(&p, &c), q, facets),
                von_mises: von_mises(material, data, q)?,
            })
        }
    }
}
