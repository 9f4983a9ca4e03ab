//! The signorini runtime: the element catalogue and quadrature, the interface compiled kernels
//! implement, meshes (the Gmsh reader and the built-in generators), sparse assembly, linear
//! algebra (faer's factorizations, block-Jacobi Krylov solvers, low-rank corrections), Newton,
//! the time stepper, and mass redistribution and lumping.

/// Calls `$f::<D, N, ..>(args)` with the D and N of an element kind.
macro_rules! dispatch {
    ($kind:expr, $f:ident ($($arg:expr),* $(,)?)) => {
        dispatch!($kind, $f::<>($($arg),*))
    };
    ($kind:expr, $f:ident :: <$($g:ty),*> ($($arg:expr),* $(,)?)) => {
        match $kind {
            $crate::element::ElementKind::IntervalP1 => $f::<1, 2, $($g),*>($($arg),*),
            $crate::element::ElementKind::TriangleP1 => $f::<2, 3, $($g),*>($($arg),*),
            $crate::element::ElementKind::TriangleP2 => $f::<2, 6, $($g),*>($($arg),*),
            $crate::element::ElementKind::TetrahedronP1 => $f::<3, 4, $($g),*>($($arg),*),
            $crate::element::ElementKind::TetrahedronP2 => $f::<3, 10, $($g),*>($($arg),*),
        }
    };
}

pub mod assembly;
pub mod block_factor;
pub mod element;
pub mod elements;
pub mod evaluate;
pub mod geometry;
pub mod input;
pub mod kernel;
pub mod krylov;
pub mod library;
pub mod linalg;
pub mod lower_half;
pub mod lowrank;
pub mod lumping;
pub mod mesh;
pub mod newton;
pub mod pattern;
pub mod problem;
pub mod quadrature;
pub mod redistribute;
pub mod scheme;
pub mod test_matrices;
