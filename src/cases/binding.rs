//! Binds the compiled form library to the names schemes use (`mass`, `stiffness`, `load`,
//! `contact`, `hybrid_contact`), for a material, a contact law and case data.

use super::CaseError;
use super::static_block::ContactMethod;
use crate::forms::schemes::hybrid;
use crate::forms::{nitsche, penalty};
use crate::runtime::assembly::{Kernel, Quadrature};
use crate::runtime::kernel::{Coef, ParamError};
use crate::runtime::linalg::Structure;
use crate::runtime::mesh::Facet;
use crate::runtime::scheme::{Bound, BoundForm};

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
    Box::new(Bound { kernel, quadrature, regions })
}

fn bad(e: ParamError) -> CaseError {
    CaseError::Option(e.to_string())
}

/// The forms and the structure of the stage Jacobians (symmetric for θ = 1 and penalty).
pub fn bind<'m>(
    material: Material,
    contact: Contact<'m>,
    data: CaseData<'_>,
    quadrature: Quadrature,
) -> Result<(Vec<Slot<'m>>, Structure), CaseError> {
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
            Ok((forms, if contact.theta == 1.0 { Structure::SymmetricPositiveDefinite } else { Structure::General }))
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
            Ok((forms, Structure::SymmetricPositiveDefinite))
        }
    }
}
