//! One interpreted form bound to parameter and coef values.

use std::sync::Arc;

use signorini_compiler::ir::plan::FormPlan;
use signorini_runtime::fem::kernel::{Coef, Form, FormMeta, check_coef};

use super::{InterpretError, Unit};

/// A form of a [`super::Library`] with its parameters and coefs, for cells of one dimension.
/// Implements `Form`, `FormKernel<D, N>` and `FunctionalKernel<D, N>` like a generated form;
/// its kernels must be called with `D` equal to [`InterpretedForm::dim`].
#[derive(Clone)]
pub struct InterpretedForm {
    unit: Arc<Unit>,
    form: usize,
    dim: usize,
    /// Values of the unit's parameters, in declaration order.
    pub(super) params: Vec<f64>,
    /// Values of the unit's coefs, in declaration order.
    pub(super) coefs: Vec<Coef>,
}

impl InterpretedForm {
    pub(super) fn new(
        unit: Arc<Unit>,
        name: &str,
        dim: usize,
        params: &[(&str, f64)],
        coefs: &[(&str, Coef)],
    ) -> Result<Self, InterpretError> {
        let Some(form) = unit.forms.iter().position(|f| f.meta.name == name) else {
            return Err(InterpretError::UnknownForm {
                name: name.to_string(),
                file: unit.file.clone(),
                available: unit.forms.iter().map(|f| f.meta.name.to_string()).collect(),
            });
        };
        if !(1..=3).contains(&dim) {
            return Err(InterpretError::Dimension(dim));
        }
        for (given, _) in coefs {
            if !unit.coefs.iter().any(|c| c.name == *given) {
                return Err(InterpretError::UnknownCoef {
                    name: given.to_string(),
                    known: unit.coefs.iter().map(|c| c.name.clone()).collect(),
                });
            }
        }
        let coefs = unit
            .coefs
            .iter()
            .map(|decl| {
                let Some((_, c)) = coefs.iter().rev().find(|(n, _)| *n == decl.name) else {
                    return Err(InterpretError::MissingCoef { name: decl.name.clone(), at: decl.at.clone() });
                };
                check_coef(&decl.name, c, decl.rank, dim).map_err(|e| InterpretError::CoefShape(e.0))?;
                Ok(c.clone())
            })
            .collect::<Result<Vec<_>, _>>()?;
        let defaults = unit.params.iter().map(|p| p.default).collect();
        let mut f = InterpretedForm { unit, form, dim, params: defaults, coefs };
        for (name, value) in params {
            f.set_param(name, *value)?;
        }
        Ok(f)
    }

    /// The dimension of the cells this form was bound for.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The value of a parameter by name.
    pub fn param(&self, name: &str) -> Option<f64> {
        self.unit.params.iter().position(|p| p.name == name).map(|i| self.params[i])
    }

    /// Sets a parameter by name, refusing unknown names and values outside the declared range.
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<(), InterpretError> {
        let Some(i) = self.unit.params.iter().position(|p| p.name == name) else {
            return Err(InterpretError::UnknownParam {
                name: name.to_string(),
                known: self.unit.params.iter().map(|p| p.name.clone()).collect(),
            });
        };
        self.params[i] = self.unit.params[i].check(value)?;
        Ok(())
    }

    /// `set_param`, by value.
    pub fn with_param(mut self, name: &str, value: f64) -> Result<Self, InterpretError> {
        self.set_param(name, value)?;
        Ok(self)
    }

    /// The kernels for cells of dimension `D`.
    pub(super) fn kernels<const D: usize>(&self) -> &FormPlan {
        // Calling a kernel with another dimension is a programming error, like a wrongly sized
        // array: the coefs were checked for `dim` only.
        assert!(D == self.dim, "interpreted form `{}` is bound for dimension {}, not {D}", self.meta().name, self.dim);
        &self.unit.forms[self.form].dims[D - 1]
    }

    /// A contact pair's law: the pointwise programs of its facet integrals in the bound
    /// dimension.
    pub(super) fn pair_integrals(&self) -> Option<&[signorini_compiler::ir::pair::PairIntegral]> {
        self.unit.forms[self.form].pairs.as_ref().map(|dims| dims[self.dim - 1].as_slice())
    }

    /// Whether the form is one of a pair law integrated over both surfaces of its pair.
    pub(super) fn over_both_sides(&self) -> bool {
        self.unit.forms[self.form].both_sides
    }

    /// Whether the form is one of a contact pair's law.
    pub fn is_pair(&self) -> bool {
        self.unit.forms[self.form].pairs.is_some()
    }
}

impl std::fmt::Debug for InterpretedForm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let params: Vec<(&str, f64)> =
            self.unit.params.iter().map(|p| p.name.as_str()).zip(self.params.clone()).collect();
        let coefs: Vec<(&str, &Coef)> = self.unit.coefs.iter().map(|c| c.name.as_str()).zip(&self.coefs).collect();
        f.debug_struct("InterpretedForm")
            .field("name", &self.meta().name)
            .field("file", &self.unit.file)
            .field("dim", &self.dim)
            .field("params", &params)
            .field("coefs", &coefs)
            .finish()
    }
}

impl Form for InterpretedForm {
    fn meta(&self) -> &FormMeta {
        &self.unit.forms[self.form].meta
    }
}
