//! Bounded reading of input files. A reader stops at its format's limit with a message that
//! names it, so a device or a wrong path (`/dev/zero`, a log given for a mesh) cannot fill the
//! memory; pipes and devices are read incrementally up to the limit.

use std::io::Read;
use std::path::Path;

/// Gmsh files: a million P2 tetrahedra in ASCII are about 150 MB.
pub const MAX_MESH_BYTES: u64 = 1 << 30;
/// TOML case files.
pub const MAX_CASE_FILE_BYTES: u64 = 1 << 20;
/// Checkpoints and their logs (the states of a run of a few million unknowns).
pub const MAX_CHECKPOINT_BYTES: u64 = 8 << 30;

/// The bytes of `path`, or an error if it holds more than `limit` bytes (`what` names the
/// kind of file in the message).
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(std::io::Error::other(format!(
            "larger than {}, the limit of a {what} (not a {what}?)",
            size(limit)
        )));
    }
    Ok(bytes)
}

/// A size in bytes for people: 1 MiB, 1 GiB.
fn size(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 => format!("{} MiB", b >> 20),
        b => format!("{b} bytes"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_is_read_up_to_the_limit_only() {
        let e = read_bounded(Path::new("/dev/zero"), 4096, "mesh file").unwrap_err().to_string();
        assert!(e.contains("larger than 4096 bytes, the limit of a mesh file"), "{e}");
        let dir = std::env::temp_dir().join(format!("signorini-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("small.msh");
        std::fs::write(&file, b"0123").unwrap();
        assert_eq!(read_bounded(&file, 4, "mesh file").unwrap(), b"0123");
        assert!(read_bounded(&file, 3, "mesh file").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
