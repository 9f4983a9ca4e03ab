//! With the `petsc` feature: links the system PETSc (3.18, the API `linalg/petsc/sys.rs`
//! declares) and Open MPI, found by pkg-config.

fn main() {
    #[cfg(feature = "petsc")]
    petsc();
}

#[cfg(feature = "petsc")]
fn petsc() {
    let found = pkg_config::Config::new().range_version("3.18".."3.19").probe("PETSc");
    if let Err(e) = found {
        panic!(
            "the `petsc` feature needs PETSc 3.18 with its pkg-config file (Debian: apt-get install libpetsc-real3.18-dev libopenmpi-dev openmpi-bin): {e}"
        );
    }
    if let Err(e) = pkg_config::probe_library("ompi-c") {
        panic!("the `petsc` feature needs Open MPI's pkg-config file (Debian: apt-get install libopenmpi-dev): {e}");
    }
}
