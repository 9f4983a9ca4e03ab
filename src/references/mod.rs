//! Analytic references a problem names (`reference NAME`): Rust functions that compare a run
//! with a known solution, read in the problem's columns as functionals of the state
//! (`exact_u_error(u)`). A new reference is a module here and a line in [`ALL`]; the problem
//! file says what it measures with it.

use crate::runtime::linalg::Matrix;
use crate::runtime::mesh::Mesh;

pub mod bar;

/// What a reference checks of a run before it describes it.
pub struct RunFacts<'a> {
    pub mesh: &'a Mesh,
    /// A param of the files in use, by name.
    pub param: &'a dyn Fn(&str) -> Option<f64>,
    pub t_start: f64,
}

/// An analytic solution's functionals.
pub trait Reference: Sync {
    fn name(&self) -> &'static str;
    /// One line for `signorini list`.
    fn doc(&self) -> &'static str;
    /// The dimension of the problems it describes.
    fn dim(&self) -> usize;
    /// Its functionals: name and meaning.
    fn functionals(&self) -> Vec<(&'static str, &'static str)>;
    /// The reference for one run, or why the run is not one it describes (another material,
    /// domain or start).
    fn bind(&self, run: &RunFacts) -> Result<Box<dyn BoundReference>, String>;
}

/// A reference bound to a run.
pub trait BoundReference {
    /// Functional `which` (an index into [`Reference::functionals`]) at displacement `u`, time
    /// `t`; `mass` is the mass the scheme steps with (for errors in its norm).
    fn value(&self, which: usize, mass: &Matrix, u: &[f64], t: f64) -> f64;
}

/// A reference and its binding to a run.
pub type Bound = (&'static dyn Reference, Box<dyn BoundReference>);

/// Every reference, by name.
pub const ALL: &[&dyn Reference] = &[&bar::Bar];

/// The reference called `name`.
pub fn find(name: &str) -> Option<&'static dyn Reference> {
    ALL.iter().copied().find(|r| r.name() == name)
}
