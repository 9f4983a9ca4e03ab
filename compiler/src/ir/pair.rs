//! The pointwise programs of a contact pair's law in one dimension: per facet integral, the
//! residual's coefficients of both sides' test functions, the tangent's four blocks per field
//! argument, and a functional's integrand, each a [`Program`] whose leaves are read on the two
//! sides of a pair point. The runtime weights and contracts them (`runtime::fem::pair`), in the
//! layout `runtime::fem::pair::layout` names.

use super::eval::Program;
use super::{DimIr, FormIr, TangentIr};

/// One facet integral of a pair law's form.
#[derive(Debug)]
pub struct PairIntegral {
    pub region: String,
    /// Roots f0 (d), f1 (d²), h0 (d), h1 (d²); `None` for a functional.
    pub residual: Option<Program>,
    /// Per field argument: the blocks (own, own), (own, facing), (facing, own), (facing,
    /// facing), each c00 (d²), c01 (d³), c10 (d³), c11 (d⁴); then the residual's coefficients
    /// and their rates as the facing point slides (`PairIr::sliding`), for the tangent's part
    /// through the facing point's motion.
    pub tangents: Vec<Program>,
    /// A functional's integrand.
    pub value: Option<Program>,
}

/// The facet integrals of a pair law's `form`, in the order of its facet regions; `None` for a
/// form of another file.
pub fn plan(ir: &DimIr, form: &FormIr) -> Option<Vec<PairIntegral>> {
    if !form.pair {
        return None;
    }
    let block = |t: &TangentIr| t.c00.iter().chain(&t.c01).chain(&t.c10).chain(&t.c11).copied().collect::<Vec<_>>();
    let integrals = form
        .integrals
        .iter()
        .filter(|i| !i.cell)
        .map(|i| {
            let residual = i.pair.as_ref().map(|p| {
                let roots: Vec<_> = i.f0.iter().chain(&i.f1).chain(&p.h0).chain(&p.h1).copied().collect();
                Program::new(&ir.graph, &roots)
            });
            let tangents = match &i.pair {
                Some(p) => i
                    .tangents
                    .iter()
                    .zip(&p.tangents)
                    .map(|(own, [of, fo, ff])| {
                        let mut roots: Vec<_> = [own, of, fo, ff].into_iter().flat_map(block).collect();
                        roots.extend(i.f0.iter().chain(&i.f1).chain(&p.h0).chain(&p.h1));
                        roots.extend(&p.sliding);
                        Program::new(&ir.graph, &roots)
                    })
                    .collect(),
                None => Vec::new(),
            };
            let value = i.value.map(|v| Program::new(&ir.graph, &[v]));
            PairIntegral { region: i.region.clone(), residual, tangents, value }
        })
        .collect();
    Some(integrals)
}
