//! The form library as data. Every `.wf` file, compiled by the macro or interpreted at run time,
//! describes itself to the runtime with a [`Unit`]: its params (defaults, ranges, docs and where
//! they are declared), its coefs, the slots its forms provide, its schemes and the slots they
//! apply, and functions that instantiate them. Cases bind slots by name; nothing in Rust names a
//! scheme, a contact law or a param.

use std::fmt;

use signorini_descriptors::{CoefInfo, ParamError, ParamInfo, SchemeDesc, SlotInfo};

use crate::fem::assembly::{Functional, Kernel, Quadrature};
use crate::fem::bound::{Bound, BoundForm, BoundFunctional, BoundValue};
use crate::fem::kernel::{Coef, FormMeta};
use crate::fem::mesh::{Body, Facet};
use crate::fem::pair::assembly::PairForm;
use crate::fem::pair::{PairKernel, Surfaces};
use crate::fem::summed::{Summed, SummedFunctional};
use crate::time::scheme::TimeScheme;

/// What a form file's forms are bound to: the quadrature, and the mesh facets of every boundary
/// region (by its name in the .wf files, e.g. `Gamma_C`).
pub struct Binding<'m> {
    pub quadrature: Quadrature,
    pub regions: Vec<(String, &'m [Facet])>,
    /// The space dimension (coef sizes are checked against it).
    pub dim: usize,
    /// The cells of the forms' volume integrals, if not all (a body's: per cell, whether it is
    /// one).
    pub cells: Option<&'m [bool]>,
    /// The mesh's bodies, when it has several: the files' forms are then bound to each body
    /// with its own param values ([`Binding::body`]) and summed.
    pub bodies: &'m [Body],
    /// The contact pairs a pair law (a file that reads `opposite`) is bound to: each once, by
    /// the body whose surface the law integrates over ([`Binding::body`]).
    pub pairs: Vec<Surfaces<'m>>,
}

impl<'m> Binding<'m> {
    /// A binding of the whole mesh (one body) to `regions`.
    pub fn new(quadrature: Quadrature, regions: Vec<(String, &'m [Facet])>, dim: usize) -> Self {
        Binding { quadrature, regions, dim, cells: None, bodies: &[], pairs: Vec::new() }
    }

    /// This binding cut to `body`: its cells, the facets they carry, and the pairs (a pair law
    /// binds those whose surface it integrates over is this body's, [`Binding::pair`]).
    pub fn body(&self, body: &'m Body) -> Binding<'m> {
        let (regions, pairs) = (self.regions.clone(), self.pairs.clone());
        Binding { quadrature: self.quadrature, regions, dim: self.dim, cells: Some(&body.cells), bodies: &[], pairs }
    }

    /// This binding with only the pairs `which` (indices into its pairs): a pair law of its
    /// own for some of a problem's pairs.
    pub fn with_pairs(&self, which: &[usize]) -> Binding<'m> {
        let pairs = which.iter().map(|&i| self.pairs[i]).collect();
        Binding { quadrature: self.quadrature, regions: self.regions.clone(), pairs, ..*self }
    }

    /// The pairs a pair law integrates over in this binding, each as (own, facing) surfaces:
    /// those whose own surface is in the binding's cells, and with `both_sides` the reversed
    /// pairs whose facing surface is (a pair law reads the params of the body it integrates
    /// over). A pair this binding integrates over in neither direction is kept with no own
    /// facet, so that every body binds the law's slots.
    fn sides(&self, both_sides: bool) -> Vec<Surfaces<'m>> {
        let mine = |s: &[Facet]| s.first().is_some_and(|f| self.cells.is_none_or(|c| c[f.cell as usize]));
        let mut out = Vec::new();
        for p in &self.pairs {
            let forward = mine(p.own).then_some(*p);
            let backward = (both_sides && mine(p.facing)).then_some(Surfaces { own: p.facing, facing: p.own, ..*p });
            match (forward, backward) {
                (None, None) => out.push(Surfaces { own: &[], ..*p }),
                (f, b) => out.extend(f.into_iter().chain(b)),
            }
        }
        out
    }
}

/// A form or functional bound to a mesh.
pub enum SlotForm<'m> {
    Form(Box<dyn BoundForm + 'm>),
    Functional(Box<dyn BoundFunctional + 'm>),
}

/// The forms of a file, instantiated: (slot name, bound form). Generated code names them with
/// `'static` text; a file interpreted at run time, with its own slots' names.
pub type Made<'s, 'm> = Vec<(&'s str, SlotForm<'m>)>;

/// Instantiates a file's forms: values of `params` in order, coefs by name.
pub type MakeForms =
    for<'m> fn(&[f64], &dyn Fn(&str) -> Option<Coef>, &Binding<'m>) -> Result<Made<'static, 'm>, LibraryError>;

/// Instantiates a scheme with the values of its params, in order.
pub type MakeScheme = fn(&[f64]) -> Result<Box<dyn TimeScheme>, LibraryError>;

/// The forms of one file.
#[derive(Clone, Copy)]
pub struct FormUnit {
    /// Every param the file's forms read, its imports' included, in `Params` order.
    pub params: &'static [ParamInfo],
    pub coefs: &'static [CoefInfo],
    /// The forms and functionals declared in the file itself.
    pub slots: &'static [SlotInfo],
    /// The roles its files import (`import material = elasticity`): the role, and the file
    /// stem compiled in its place. A run that binds another file to the role compiles the
    /// file again, at run time, with that one.
    pub roles: &'static [(&'static str, &'static str)],
    pub make: MakeForms,
}

/// A scheme of a file.
#[derive(Clone, Copy)]
pub struct SchemeUnit {
    pub name: &'static str,
    /// The comment block above the scheme.
    pub doc: &'static str,
    pub params: &'static [ParamInfo],
    /// Its stages, terms and the slots it applies.
    pub desc: &'static SchemeDesc,
    pub make: MakeScheme,
}

/// Everything a `.wf` file tells the runtime about itself.
#[derive(Clone, Copy)]
pub struct Unit {
    /// The file stem.
    pub name: &'static str,
    /// The path as given to the compiler.
    pub file: &'static str,
    /// The comment block at the top of the file.
    pub doc: &'static str,
    pub forms: Option<FormUnit>,
    pub schemes: &'static [SchemeUnit],
}

/// Units are constants: one is another if it has the same name and file.
impl PartialEq for Unit {
    fn eq(&self, other: &Unit) -> bool {
        self.name == other.name && self.file == other.file
    }
}

impl fmt::Debug for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Unit").field("name", &self.name).field("file", &self.file).finish_non_exhaustive()
    }
}

/// Why a file's forms or scheme could not be instantiated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LibraryError {
    #[error("{0}")]
    Param(#[from] ParamError),
    #[error("the case provides no `{name}` (`coef {name}` declared at {declared})")]
    MissingCoef { name: String, declared: String },
    #[error("{0}")]
    Coef(String),
    #[error(
        "{at}: form `{form}` integrates over `{region}`, which the case does not define (it defines: {defined}){hint}"
    )]
    MissingRegion { form: String, region: String, at: String, defined: String, hint: String },
    #[error(
        "{at}: `{form}` takes a tangential part, across the obstacle normal, which a 1D problem does not have (its only direction is the normal): a frictional law needs a 2D or 3D problem"
    )]
    NoTangentSpace { form: String, at: String },
    #[error(
        "`{form}` reads `opposite`: it is a law between two bodies, and the problem declares no contact pair (`contact Gamma_a with Gamma_b`)"
    )]
    NoPairs { form: String },
}

impl<'m> Binding<'m> {
    /// The facets of each of a form's boundary regions (`names`, named in the source at
    /// `sites`).
    fn regions_of(
        &self,
        form: &str,
        names: &[(impl AsRef<str>, [u32; 2])],
        sites: &[impl AsRef<str>],
    ) -> Result<Vec<(String, &'m [Facet])>, LibraryError> {
        names
            .iter()
            .enumerate()
            .map(|(k, (region, _))| {
                let region = region.as_ref();
                self.regions.iter().find(|(n, _)| n == region).map(|(n, f)| (n.clone(), *f)).ok_or_else(|| {
                    let defined: Vec<&str> = self.regions.iter().map(|(n, _)| n.as_str()).collect();
                    let close = defined
                        .iter()
                        .map(|d| (strsim::damerau_levenshtein(region, d), *d))
                        .filter(|(dist, d)| *dist <= 1.max(region.len() / 3) && *dist < d.len())
                        .min();
                    LibraryError::MissingRegion {
                        form: form.to_string(),
                        region: region.to_string(),
                        at: sites.get(k).map_or("(source unknown)", AsRef::as_ref).to_string(),
                        defined: if defined.is_empty() { "none".into() } else { defined.join(", ") },
                        hint: close.map_or_else(String::new, |(_, d)| format!("; did you mean `{d}`?")),
                    }
                })
            })
            .collect()
    }

    /// A form that takes tangential parts cannot be bound in 1D.
    fn tangent_space(&self, meta: &FormMeta) -> Result<(), LibraryError> {
        match &meta.tangential {
            Some(at) if self.dim == 1 => {
                Err(LibraryError::NoTangentSpace { form: meta.name.to_string(), at: at.to_string() })
            }
            _ => Ok(()),
        }
    }

    /// A form kernel bound to this mesh.
    pub fn form<K: Kernel + 'm>(&self, kernel: K) -> Result<SlotForm<'m>, LibraryError> {
        let meta = kernel.meta();
        self.tangent_space(meta)?;
        let regions = self.regions_of(&meta.name, &meta.facets, &meta.facet_sites)?;
        Ok(SlotForm::Form(Box::new(Bound { kernel, quadrature: self.quadrature, regions, cells: self.cells })))
    }

    /// A pair law's form or functional bound to every pair of this binding, summed over them.
    pub fn pair<K: PairKernel + Clone + 'm>(&self, kernel: K, functional: bool) -> Result<SlotForm<'m>, LibraryError> {
        let meta = kernel.meta();
        self.tangent_space(meta)?;
        if self.pairs.is_empty() {
            return Err(LibraryError::NoPairs { form: meta.name.to_string() });
        }
        let forms: Vec<PairForm<'m>> = self
            .sides(kernel.both_sides())
            .iter()
            .map(|p| {
                let degree = self
                    .quadrature
                    .facet
                    .unwrap_or_else(|| meta.facets.first().map_or(1, |(_, d)| d[p.kind.degree() as usize - 1]));
                PairForm::new(Box::new(kernel.clone()), 0, p.kind, p.own, p.facing, degree, p.reach)
                    .segmented(p.segmented)
            })
            .collect();
        Ok(match functional {
            false => SlotForm::Form(Box::new(Summed::new(
                forms.into_iter().map(|f| Box::new(f) as Box<dyn BoundForm + 'm>).collect(),
            ))),
            true => SlotForm::Functional(Box::new(SummedFunctional::over_bodies(
                forms.into_iter().map(|f| Box::new(f) as Box<dyn BoundFunctional + 'm>).collect(),
            ))),
        })
    }

    /// A functional kernel bound to this mesh.
    pub fn functional<K: Functional + 'm>(&self, kernel: K) -> Result<SlotForm<'m>, LibraryError> {
        let meta = kernel.meta();
        self.tangent_space(meta)?;
        let regions = self.regions_of(&meta.name, &meta.facets, &meta.facet_sites)?;
        let cells = self.cells;
        Ok(SlotForm::Functional(Box::new(BoundValue { kernel, quadrature: self.quadrature, regions, cells })))
    }
}

/// The coef `name` from the case, or an error naming its declaration.
pub fn need_coef(coefs: &dyn Fn(&str) -> Option<Coef>, info: &CoefInfo) -> Result<Coef, LibraryError> {
    coefs(&info.name)
        .ok_or_else(|| LibraryError::MissingCoef { name: info.name.to_string(), declared: info.declared.to_string() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_region_is_reported_at_its_source_with_a_suggestion() {
        let binding = Binding::new(Quadrature::default(), vec![("Gamma_C".into(), &[])], 2);
        let Err(e) = binding.regions_of("contact", &[("Gamma_c", [1, 2])], &["contact.wf:3:26"]) else {
            panic!("bound an unknown region");
        };
        assert_eq!(
            e.to_string(),
            "contact.wf:3:26: form `contact` integrates over `Gamma_c`, which the case does not define (it defines: \
             Gamma_C); did you mean `Gamma_C`?"
        );
    }
}
