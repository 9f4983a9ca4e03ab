//! Analytic references a problem names (`reference NAME`): Rust functions that compare a run
//! with a known solution, read in the problem's columns as functionals of the state
//! (`exact_u_error(u)`). A new reference is a module here and a line in [`ALL`]; the problem
//! file says what it measures with it, and gives its arguments (`reference hertz(radius = 10,
//! force = F)`).

use std::path::Path;

use crate::runtime::fem::assembly::Assembler;
use crate::runtime::fem::bound::BoundFunctional;
use crate::runtime::fem::mesh::Mesh;
use crate::runtime::linalg::Matrix;

pub mod bar;
pub mod hertz;

/// What a reference checks of a run before it describes it.
pub struct RunFacts<'a> {
    pub mesh: &'a Mesh,
    /// A param of the files in use, by name.
    pub param: &'a dyn Fn(&str) -> Option<f64>,
    pub t_start: f64,
    /// The problem's arguments to the reference, by name (checked against [`Reference::args`]).
    pub args: &'a [(String, f64)],
    /// The facets where contact is imposed (none without contact).
    pub contact: &'a [crate::runtime::fem::mesh::Facet],
}

impl RunFacts<'_> {
    /// An argument the problem gave, or why it is needed.
    pub fn arg(&self, name: &str) -> Result<f64, String> {
        self.args
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("it needs the argument `{name}` (`reference NAME({name} = ...)`)"))
    }

    /// An argument that must be positive and finite; `default` when the problem does not give
    /// it (none: it is required).
    pub fn positive(&self, name: &str, default: Option<f64>) -> Result<f64, String> {
        if let Some(d) = default
            && !self.args.iter().any(|(n, _)| n == name)
        {
            return Ok(d);
        }
        let v = self.arg(name)?;
        if v > 0.0 && v.is_finite() { Ok(v) } else { Err(format!("`{name}` must be positive, not {v}")) }
    }

    /// An argument, or `default` when the problem does not give it.
    pub fn arg_or(&self, name: &str, default: f64) -> f64 {
        self.arg(name).unwrap_or(default)
    }
}

/// One state of the run, as a reference measures it.
pub struct At<'a> {
    pub asm: &'a Assembler<'a>,
    /// The mass the scheme steps with (for errors in its norm).
    pub mass: &'a Matrix,
    /// The contact law's `contact_pressure` functional, if it has one.
    pub pressure: Option<&'a dyn BoundFunctional>,
    pub u: &'a [f64],
    pub t: f64,
}

/// An analytic solution's functionals.
pub trait Reference: Sync {
    fn name(&self) -> &'static str;
    /// One line for `signorini list`.
    fn doc(&self) -> &'static str;
    /// The dimensions of the problems it describes.
    fn dims(&self) -> &'static [usize];
    /// Its arguments: name and meaning.
    fn args(&self) -> Vec<(&'static str, &'static str)> {
        Vec::new()
    }
    /// Its functionals: name and meaning.
    fn functionals(&self) -> Vec<(&'static str, &'static str)>;
    /// The reference for one run, or why the run is not one it describes (another material,
    /// domain or start).
    fn bind(&self, run: &RunFacts) -> Result<Box<dyn BoundReference>, String>;
}

/// A reference bound to a run.
pub trait BoundReference {
    /// Functional `which` (an index into [`Reference::functionals`]) at a state.
    fn value(&self, which: usize, at: &At) -> f64;

    /// Figures of the run's last state, written into its output directory (none by default).
    fn write(&self, _dir: &Path, _at: &At) -> std::io::Result<()> {
        Ok(())
    }
}

/// A reference and its binding to a run.
pub type Bound = (&'static dyn Reference, Box<dyn BoundReference>);

/// Every reference, by name.
pub const ALL: &[&dyn Reference] = &[&bar::Bar, &hertz::Hertz, &hertz::impact::HertzImpact];

/// The reference called `name`.
pub fn find(name: &str) -> Option<&'static dyn Reference> {
    ALL.iter().copied().find(|r| r.name() == name)
}
