//! Where the library's files are on disk at run time: `forms/` (whose problems name meshes
//! under `assets/meshes/` by relative paths) beside the crate that was built, or the copy a
//! package installed elsewhere carries (the Python package's), set once at start.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

static ROOT: OnceLock<PathBuf> = OnceLock::new();

/// Reads the library from `root` (holding `forms/` and `assets/meshes/`) instead of the source
/// tree this crate was built from; the first call counts.
pub fn set(root: PathBuf) {
    let _ = ROOT.set(root);
}

/// The directory holding `forms/` and `assets/`.
pub fn root() -> &'static Path {
    ROOT.get().map_or(Path::new(env!("CARGO_MANIFEST_DIR")), PathBuf::as_path)
}

/// The library's `forms/` directory.
pub fn forms() -> PathBuf {
    root().join("forms")
}
