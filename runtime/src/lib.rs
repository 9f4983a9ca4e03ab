//! The signorini runtime, in layers that import only downwards:
//!
//! - [`linalg`]: sparse matrices, factorizations, Krylov solvers, low-rank corrections;
//! - [`fem`]: elements, quadrature, geometry, meshes, the kernel interface compiled forms
//!   implement, assembly, and forms bound to a mesh;
//! - [`nonlinear`]: semi-smooth Newton and static problems;
//! - [`time`]: the stepper that runs a compiled scheme, stage by stage;
//! - [`library`]: compiled files as data (their params, coefs, slots and schemes), bound to a
//!   mesh by name;
//!
//! with [`descriptors`] (what the compiler writes about a file) shared with the compiler, and
//! [`input`] (bounded reading of files) used by every reader.

#![deny(clippy::undocumented_unsafe_blocks)]

/// Calls `$f::<D, N, ..>(args)` with the D and N of an element kind.
macro_rules! dispatch {
    ($kind:expr, $f:ident ($($arg:expr),* $(,)?)) => {
        dispatch!($kind, $f::<>($($arg),*))
    };
    ($kind:expr, $f:ident :: <$($g:ty),*> ($($arg:expr),* $(,)?)) => {
        match $kind {
            $crate::fem::element::ElementKind::IntervalP1 => $f::<1, 2, $($g),*>($($arg),*),
            $crate::fem::element::ElementKind::TriangleP1 => $f::<2, 3, $($g),*>($($arg),*),
            $crate::fem::element::ElementKind::TriangleP2 => $f::<2, 6, $($g),*>($($arg),*),
            $crate::fem::element::ElementKind::TetrahedronP1 => $f::<3, 4, $($g),*>($($arg),*),
            $crate::fem::element::ElementKind::TetrahedronP2 => $f::<3, 10, $($g),*>($($arg),*),
        }
    };
}

/// Declares `$name`: a `$per_kind` (a trait generic over an element's D and N) implemented on
/// every element kind of [`dispatch`]'s catalogue, so that code generic over a form can
/// dispatch on the kind at run time.
macro_rules! on_every_element_kind {
    ($(#[$doc:meta])* $name:ident: $per_kind:ident) => {
        $(#[$doc])*
        pub trait $name:
            Form + $per_kind<1, 2> + $per_kind<2, 3> + $per_kind<2, 6> + $per_kind<3, 4> + $per_kind<3, 10> + Sync
        {
        }
        impl<K> $name for K where
            K: Form + $per_kind<1, 2> + $per_kind<2, 3> + $per_kind<2, 6> + $per_kind<3, 4> + $per_kind<3, 10> + Sync
        {
        }
    };
}

/// The descriptions compiled files give of themselves (their own crate: the compiler writes
/// them too).
pub use signorini_descriptors as descriptors;

pub mod fem;
pub mod input;
pub mod library;
pub mod linalg;
pub mod nonlinear;
pub mod time;
