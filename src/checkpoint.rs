//! Checkpoints of a time-stepping run: every state of the scheme, the step-size controller and
//! the energy check in `DIR/checkpoint.bin`, written atomically; the case's record of the run
//! (series rows, snapshots written) in `DIR/checkpoint.log`, to which each checkpoint appends
//! what is new since the last, so that a checkpoint costs the same at every step of a long run.
//! checkpoint.bin says how much of the log it covers: a crash between the two writes leaves a
//! longer log, cut back on resume.
//!
//! `--checkpoint-every N` writes one after every N-th step and drops the stepper's
//! factorizations there; `--resume DIR` starts from DIR's checkpoint with none, so a resumed run
//! follows the same factorizations as the uninterrupted one and its results have the same bits.
//! An interrupt (SIGINT, SIGTERM) writes one after the step it finishes; resuming from that one
//! agrees to round-off only, as the uninterrupted run kept its factorizations there. A
//! checkpoint is refused unless the version of signorini, the case, the scheme, the files, every
//! param, the mesh and the time step are the ones of the run that resumes it.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::driver::FilesInUse;
use crate::error::CaseError;
use crate::runtime::fem::mesh::Mesh;

/// The files in the output directory.
pub const FILE: &str = "checkpoint.bin";
pub const LOG: &str = "checkpoint.log";
const MAGIC: &[u8; 8] = b"SIGNCKPT";
/// The layout of the file; a checkpoint of another layout is refused.
const FORMAT: u32 = 2;

/// What a run must share with the checkpoint it resumes: (what, value) pairs, compared one by
/// one so that a refusal names what differs.
pub type Identity = Vec<(String, String)>;

/// The driver's part of a checkpoint (see `simulation::Simulation::run`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DriverState {
    /// Nominal steps done.
    pub steps_done: usize,
    pub accepted: usize,
    /// The step-size controller: halvings in force, good steps since the last change, and
    /// halvings so far.
    pub level: usize,
    pub streak: usize,
    pub cuts: usize,
    /// The energy check: E(0), the largest work of the loads so far, u(0).
    pub energy_initial: f64,
    pub energy_work: f64,
    /// The work of a time-dependent load so far.
    pub energy_varying_work: f64,
    /// The contact law's own work so far (Nitsche θ ≠ 1).
    pub energy_law_work: f64,
    pub energy_u0: Vec<f64>,
    /// The largest kinetic energy so far and the largest growth (the guard's scale and record).
    pub energy_kinetic: f64,
    pub energy_growth: f64,
    /// The lowest E_aug − W so far (a dissipative scheme's bound).
    pub energy_lowest: f64,
    /// A conserving scheme's allowance so far, and its active set after the last step.
    pub energy_allowance: f64,
    pub energy_switches: Vec<bool>,
    pub states: Vec<Vec<f64>>,
    /// Written every N steps (resumes bit for bit), or on an interrupt (to round-off).
    pub periodic: bool,
}

#[derive(Serialize, Deserialize)]
struct File {
    program: String,
    identity: Identity,
    driver: DriverState,
    /// Bytes of checkpoint.log this checkpoint covers.
    log_len: u64,
}

/// When and where a run writes checkpoints, and the one it resumes.
#[derive(Default)]
pub struct Control {
    /// Steps between checkpoints (0: none, except on an interrupt).
    pub every: usize,
    /// The output directory (no checkpoints without one).
    pub dir: Option<PathBuf>,
    pub identity: Identity,
    /// The checkpoint the run resumes: the driver's part (taken by the driver) and the case's
    /// records, one per checkpoint so far, in order.
    pub resume: Option<(DriverState, Vec<Vec<u8>>)>,
    /// Whether this run has started its log (a new run empties an old one at its first write).
    log_started: bool,
}

impl Control {
    /// Checkpoints every `every` steps into `dir` for a run of this `identity`; with `resume`,
    /// the run continues from `dir`'s checkpoint (read and checked here).
    pub fn new(every: usize, dir: Option<PathBuf>, identity: Identity, resume: bool) -> Result<Control, CaseError> {
        let mut control = Control { every, dir, identity, resume: None, log_started: false };
        if resume {
            let dir =
                control.dir.as_ref().ok_or_else(|| CaseError::Option("resuming needs the run's directory".into()))?;
            control.resume = Some(read(dir, &control.identity)?);
            control.log_started = true;
        }
        Ok(control)
    }

    /// The case's records in the checkpoint being resumed (one per checkpoint), if any.
    pub fn observer(&self) -> Option<&[Vec<u8>]> {
        self.resume.as_ref().map(|(_, o)| o.as_slice())
    }

    /// Appends the case's `record` (what is new since the last checkpoint) to checkpoint.log,
    /// then writes checkpoint.bin atomically (a no-op without an output directory).
    pub fn write(&mut self, driver: DriverState, record: Vec<u8>) -> Result<(), CaseError> {
        use std::io::Write;
        let Some(dir) = &self.dir else { return Ok(()) };
        let log = dir.join(LOG);
        let log_error = |source| CaseError::Write { path: log.display().to_string(), source };
        std::fs::create_dir_all(dir).map_err(log_error)?;
        let mut f = std::fs::OpenOptions::new().create(true).append(true).open(&log).map_err(log_error)?;
        if !self.log_started {
            f.set_len(0).map_err(log_error)?;
            self.log_started = true;
        }
        f.write_all(&(record.len() as u64).to_le_bytes()).map_err(log_error)?;
        f.write_all(&record).map_err(log_error)?;
        f.sync_data().map_err(log_error)?;
        let log_len = f.metadata().map_err(log_error)?.len();
        let file = File { program: program(), identity: self.identity.clone(), driver, log_len };
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&FORMAT.to_le_bytes());
        bytes.extend(postcard::to_stdvec(&file).map_err(|e| write_error(dir, std::io::Error::other(e)))?);
        let path = dir.join(FILE);
        crate::output::write_atomic(&path, &bytes).map_err(|e| write_error(dir, e))
    }
}

fn write_error(dir: &Path, source: std::io::Error) -> CaseError {
    CaseError::Write { path: dir.join(FILE).display().to_string(), source }
}

fn program() -> String {
    format!("signorini {}", env!("CARGO_PKG_VERSION"))
}

/// Reads `dir`/checkpoint.bin and the part of checkpoint.log it covers (cutting the log back to
/// it), and checks it against the run's `identity`.
pub fn read(dir: &Path, identity: &Identity) -> Result<(DriverState, Vec<Vec<u8>>), CaseError> {
    let path = dir.join(FILE);
    let refuse = |why: String| CaseError::Option(format!("cannot resume from {}: {why}", path.display()));
    use crate::runtime::input::{MAX_CHECKPOINT_BYTES, read_bounded};
    let bytes = read_bounded(&path, MAX_CHECKPOINT_BYTES, "checkpoint").map_err(|e| refuse(e.to_string()))?;
    if bytes.len() < 12 || &bytes[..8] != MAGIC {
        return Err(refuse("not a signorini checkpoint".into()));
    }
    let format = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if format != FORMAT {
        return Err(refuse(format!("its layout is version {format}; this signorini reads version {FORMAT}")));
    }
    let file: File =
        postcard::from_bytes(&bytes[12..]).map_err(|e| refuse(format!("the file is damaged or truncated ({e})")))?;
    if file.program != program() {
        return Err(refuse(format!("it was written by {}; this is {}", file.program, program())));
    }
    for (what, value) in identity {
        match file.identity.iter().find(|(w, _)| w == what) {
            Some((_, old)) if old == value => {}
            Some((_, old)) => {
                return Err(refuse(format!("it was written with {what} {old}; this run has {what} {value}")));
            }
            None => return Err(refuse(format!("it does not record {what} (this run has {value})"))),
        }
    }
    if let Some((what, _)) = file.identity.iter().find(|(w, _)| !identity.iter().any(|(v, _)| v == w)) {
        return Err(refuse(format!("it records {what}, which this run does not have")));
    }
    let log = dir.join(LOG);
    let bytes = read_bounded(&log, MAX_CHECKPOINT_BYTES, "checkpoint log")
        .map_err(|e| refuse(format!("{}: {e}", log.display())))?;
    let covered = usize::try_from(file.log_len).ok().filter(|&n| n <= bytes.len());
    let Some(covered) = covered else {
        return Err(refuse(format!("{} is shorter than the checkpoint says", log.display())));
    };
    let mut records = Vec::new();
    let mut at = 0;
    while at < covered {
        let len = bytes.get(at..at + 8).map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")) as usize);
        let Some(record) = len.and_then(|n| bytes.get(at + 8..at + 8 + n)).filter(|_| at + 8 <= covered) else {
            return Err(refuse(format!("{} is damaged", log.display())));
        };
        records.push(record.to_vec());
        at += 8 + record.len();
    }
    // What a crash appended after the checkpoint is dropped: the resumed run redoes it.
    std::fs::OpenOptions::new()
        .write(true)
        .open(&log)
        .and_then(|f| f.set_len(covered as u64))
        .map_err(|e| refuse(format!("{}: {e}", log.display())))?;
    Ok((file.driver, records))
}

/// What a resumed run must share with its checkpoint: the case, the scheme, the files and every
/// param in use, the step guard, the mesh, and the case's own settings (`more`).
pub fn identity(case: &str, in_use: &FilesInUse, mesh: &Mesh, more: &[(&str, String)]) -> Identity {
    let common = [
        ("case", case.to_string()),
        ("scheme", in_use.scheme_name().to_string()),
        ("contact law", in_use.forms.contact_name().to_string()),
        ("files run interpreted", in_use.interpreted().join(", ")),
        ("step guard", format!("{:?}", in_use.guard)),
        ("mesh", mesh_fingerprint(mesh)),
    ];
    let params =
        in_use.forms.params.values().into_iter().map(|(name, p)| (format!("param {name}"), format!("{:?}", p.value)));
    // A file run by path may be edited between the stop and the resume: its text counts.
    let texts = in_use.interpreted().into_iter().map(|file| {
        let text = std::fs::read(&file).map_or_else(|e| format!("unreadable ({e})"), |b| format!("{:016x}", fnv(&b)));
        (format!("text of {file}"), text)
    });
    common
        .into_iter()
        .chain(more.iter().map(|(k, v)| (*k, v.clone())))
        .map(|(k, v)| (k.to_string(), v))
        .chain(params)
        .chain(texts)
        .collect()
}

/// The mesh's size and a hash of its coordinates (their bits), cells and named regions.
pub fn mesh_fingerprint(mesh: &Mesh) -> String {
    let mut bytes = Vec::new();
    for i in 0..mesh.num_nodes() {
        mesh.node(i).iter().for_each(|x| bytes.extend(x.to_bits().to_le_bytes()));
    }
    for c in 0..mesh.num_cells() {
        mesh.cell(c).iter().for_each(|&n| bytes.extend(n.to_le_bytes()));
    }
    for r in &mesh.regions {
        bytes.extend(r.name.as_bytes());
        r.facets.iter().for_each(|f| bytes.extend(f.cell.to_le_bytes().into_iter().chain([f.local])));
    }
    format!("of {} nodes and {} cells (hash {:016x})", mesh.num_nodes(), mesh.num_cells(), fnv(&bytes))
}

/// FNV-1a: stable across builds and platforms, unlike std's hasher.
pub fn fnv(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn driver() -> DriverState {
        DriverState {
            steps_done: 3,
            accepted: 4,
            level: 1,
            streak: 0,
            cuts: 1,
            energy_initial: 1.5,
            energy_work: 0.0,
            energy_varying_work: 0.0,
            energy_law_work: 0.0,
            energy_u0: vec![0.0, 1.0],
            energy_kinetic: 0.5,
            energy_growth: 0.0,
            energy_lowest: 1.5,
            energy_allowance: 0.0,
            energy_switches: vec![true],
            states: vec![vec![f64::NAN, -0.0, 1e-300], vec![f64::INFINITY, 2.0, 3.0]],
            periodic: true,
        }
    }

    fn ident(dt: &str) -> Identity {
        vec![("case".into(), "disc".into()), ("dt".into(), dt.into())]
    }

    #[test]
    fn a_checkpoint_reads_back_bit_for_bit_and_refuses_another_run() {
        let dir = std::env::temp_dir().join(format!("signorini-checkpoint-{}", std::process::id()));
        let mut control = Control::new(3, Some(dir.clone()), ident("0.02"), false).unwrap();
        control.write(driver(), vec![7, 8, 9]).unwrap();
        control.write(driver(), vec![10]).unwrap();
        // A record appended by a run that crashed before its checkpoint.bin: cut on resume.
        std::fs::OpenOptions::new()
            .append(true)
            .open(dir.join(LOG))
            .and_then(|mut f| std::io::Write::write_all(&mut f, &[1, 0, 0, 0, 0, 0, 0, 0, 11]))
            .unwrap();
        let (d, o) = read(&dir, &ident("0.02")).unwrap();
        assert_eq!(std::fs::metadata(dir.join(LOG)).unwrap().len(), 8 + 3 + 8 + 1);
        let bits = |s: &DriverState| s.states.iter().flatten().map(|x| x.to_bits()).collect::<Vec<u64>>();
        assert_eq!(bits(&d), bits(&driver()));
        assert_eq!((d.steps_done, d.accepted, d.level, d.cuts, o), (3, 4, 1, 1, vec![vec![7, 8, 9], vec![10]]));
        let e = read(&dir, &ident("0.01")).unwrap_err().to_string();
        assert!(e.contains("written with dt 0.02; this run has dt 0.01"), "{e}");
        // A truncated file is refused, not half read.
        let path = dir.join(FILE);
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let e = read(&dir, &ident("0.02")).unwrap_err().to_string();
        assert!(e.contains("damaged or truncated"), "{e}");
        std::fs::write(&path, b"hello").unwrap();
        assert!(read(&dir, &ident("0.02")).unwrap_err().to_string().contains("not a signorini checkpoint"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
