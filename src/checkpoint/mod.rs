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
//!
//! In a run of several processes rank 0 writes these files; in a split run each process also
//! writes its own rows of the states ([`parts`]), and the processes agree that every part was
//! written before rank 0 writes the manifest. Any number of processes resumes any checkpoint.

mod parts;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::driver::FilesInUse;
use crate::error::CaseError;
use crate::runtime::fem::mesh::Mesh;
use crate::runtime::linalg::ownership::Ownership;
use crate::runtime::linalg::pattern::Owners;
use crate::runtime::linalg::ranks;

/// The files in the output directory.
pub const FILE: &str = "checkpoint.bin";
pub const LOG: &str = "checkpoint.log";
const MAGIC: &[u8; 8] = b"SIGNCKPT";
/// The layout of the file; a checkpoint of another layout is refused.
const FORMAT: u32 = 6;

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
    /// What the law's friction took so far (`friction_work`).
    pub energy_dissipated: f64,
    /// (In a split run's manifest, this and `states` are empty: the parts hold them.)
    pub energy_u0: Vec<f64>,
    /// The largest kinetic energy so far and the largest growth (the guard's scale and record).
    pub energy_kinetic: f64,
    pub energy_growth: f64,
    /// The energy the steps made so far (net of allowances) and the least it was (a
    /// dissipative scheme's bound).
    pub energy_made: f64,
    pub energy_lowest: f64,
    /// E_aug and the work of the loads at the last step's end.
    pub energy_last: f64,
    pub energy_external: f64,
    /// The active set after the last step (a conserving scheme's).
    pub energy_switches: Vec<bool>,
    /// The scheme's states, then the previous time level when a law reads it (`prev`).
    pub states: Vec<Vec<f64>>,
    /// Written every N steps (resumes bit for bit), or on an interrupt (to round-off).
    pub periodic: bool,
    /// An adaptive run's time, step controller and counts.
    pub adaptive: Option<crate::simulation::step_control::AdaptiveState>,
}

#[derive(Serialize, Deserialize)]
struct File {
    program: String,
    identity: Identity,
    driver: DriverState,
    /// Bytes of checkpoint.log this checkpoint covers.
    log_len: u64,
    /// A split run's parts, which hold the states.
    parts: Option<parts::Layout>,
}

/// When and where a run writes checkpoints, and the one it resumes (made by [`Control::new`],
/// which decides which process writes).
pub struct Control {
    /// Steps between checkpoints (0: none, except on an interrupt).
    pub every: usize,
    /// The output directory (no checkpoints without one), the same on every process.
    pub dir: Option<PathBuf>,
    pub identity: Identity,
    /// The checkpoint the run resumes: the driver's part (taken by the driver) and the case's
    /// records, one per checkpoint so far, in order.
    pub resume: Option<(DriverState, Vec<Vec<u8>>)>,
    /// Whether this run has started its log (a new run empties an old one at its first write).
    log_started: bool,
    /// A split run's ownership: each process writes its own rows.
    split: Option<Arc<Ownership>>,
    /// Whether this process writes the log and the manifest (rank 0).
    writer: bool,
    /// Checkpoints written so far, the resumed one's included.
    generation: u64,
}

impl Control {
    /// Checkpoints every `every` steps into `dir` for a run of this `identity`, split across
    /// processes by `split` (None: one process, or processes that each hold the whole run);
    /// with `resume`, the run continues from `dir`'s checkpoint (read and checked here;
    /// collective in a split run).
    pub fn new(
        every: usize,
        dir: Option<PathBuf>,
        identity: Identity,
        resume: bool,
        split: Option<Arc<Ownership>>,
    ) -> Result<Control, CaseError> {
        let writer = split.as_ref().map_or_else(ranks::writes, |o| o.rank() == 0);
        let mut control =
            Control { every, dir, identity, resume: None, log_started: false, split, writer, generation: 0 };
        if resume {
            let dir =
                control.dir.as_ref().ok_or_else(|| CaseError::Option("resuming needs the run's directory".into()))?;
            let (driver, records) = read(dir, &control.identity, control.split.as_deref(), control.writer)?;
            control.generation = records.len() as u64;
            control.resume = Some((driver, records));
            control.log_started = true;
        }
        Ok(control)
    }

    /// The case's records in the checkpoint being resumed (one per checkpoint), if any.
    pub fn observer(&self) -> Option<&[Vec<u8>]> {
        self.resume.as_ref().map(|(_, o)| o.as_slice())
    }

    /// Appends the case's `record` (what is new since the last checkpoint) to checkpoint.log,
    /// then writes checkpoint.bin atomically (a no-op without an output directory). In a run of
    /// several processes every process calls it at the same step, and every process fails if
    /// one could not write its share.
    pub fn write(&mut self, mut driver: DriverState, record: Vec<u8>) -> Result<(), CaseError> {
        let Some(dir) = self.dir.clone() else { return Ok(()) };
        self.generation += 1;
        let mut layout = None;
        if let Some(o) = &self.split {
            let wrote = parts::write(&dir, o, self.generation, &driver.states, &driver.energy_u0);
            agree(
                wrote.map_err(|e| CaseError::Write {
                    path: dir.display().to_string(),
                    source: std::io::Error::other(e),
                }),
            )?;
            layout = Some(parts::layout(o, self.generation));
            driver.states.clear();
            driver.energy_u0.clear();
        }
        let wrote = if self.writer { self.write_manifest(&dir, driver, record, layout) } else { Ok(()) };
        agree(wrote)
    }

    fn write_manifest(
        &mut self,
        dir: &Path,
        driver: DriverState,
        record: Vec<u8>,
        parts: Option<parts::Layout>,
    ) -> Result<(), CaseError> {
        use std::io::Write;
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
        let file = File { program: program(), identity: self.identity.clone(), driver, log_len, parts };
        let bytes = encode(&file, MAGIC, FORMAT).map_err(|e| write_error(dir, std::io::Error::other(e)))?;
        let path = dir.join(FILE);
        crate::output::write_atomic(&path, &bytes).map_err(|e| write_error(dir, e))
    }
}

/// `result` on this process, and a failure on every process if any process failed (collective
/// in a run of several processes).
fn agree(result: Result<(), CaseError>) -> Result<(), CaseError> {
    match ranks::any(result.is_err()) {
        Err(e) => Err(CaseError::Option(format!("MPI: {e}"))),
        Ok(true) if result.is_ok() => Err(CaseError::Option(
            "another process could not write its share of the checkpoint (its error says why)".into(),
        )),
        Ok(_) => result,
    }
}

/// `value` as `magic`, the layout version `format` and postcard ([`decode`] reads it).
fn encode(value: &impl Serialize, magic: &[u8; 8], format: u32) -> Result<Vec<u8>, postcard::Error> {
    let mut bytes = magic.to_vec();
    bytes.extend_from_slice(&format.to_le_bytes());
    bytes.extend(postcard::to_stdvec(value)?);
    Ok(bytes)
}

/// The value in `bytes`, written as `magic`, the layout version and postcard: refused, saying
/// why, if it is not `what`, of another layout, or damaged.
fn decode<T: serde::de::DeserializeOwned>(bytes: &[u8], magic: &[u8; 8], format: u32, what: &str) -> Result<T, String> {
    if bytes.len() < 12 || &bytes[..8] != magic {
        return Err(format!("not {what}"));
    }
    let found = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if found != format {
        return Err(format!("its layout is version {found}; this signorini reads version {format}"));
    }
    postcard::from_bytes(&bytes[12..]).map_err(|e| format!("the file is damaged or truncated ({e})"))
}

fn write_error(dir: &Path, source: std::io::Error) -> CaseError {
    CaseError::Write { path: dir.join(FILE).display().to_string(), source }
}

fn program() -> String {
    format!("signorini {}", env!("CARGO_PKG_VERSION"))
}

/// Reads `dir`/checkpoint.bin, the states of a split checkpoint from its parts (collective when
/// `split` splits as the checkpoint's run did), and the part of checkpoint.log the checkpoint
/// covers (the `writer` cuts the log back to it); checks it against the run's `identity`.
fn read(
    dir: &Path,
    identity: &Identity,
    split: Option<&Ownership>,
    writer: bool,
) -> Result<(DriverState, Vec<Vec<u8>>), CaseError> {
    let path = dir.join(FILE);
    let refuse = |why: String| CaseError::Option(format!("cannot resume from {}: {why}", path.display()));
    use crate::runtime::input::{MAX_CHECKPOINT_BYTES, read_bounded};
    let bytes = read_bounded(&path, MAX_CHECKPOINT_BYTES, "checkpoint").map_err(|e| refuse(e.to_string()))?;
    let file: File = decode(&bytes, MAGIC, FORMAT, "a signorini checkpoint").map_err(refuse)?;
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
    let mut driver = file.driver;
    if let Some(layout) = &file.parts {
        (driver.states, driver.energy_u0) = parts::read(dir, layout, split).map_err(refuse)?;
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
    if writer {
        std::fs::OpenOptions::new()
            .write(true)
            .open(&log)
            .and_then(|f| f.set_len(covered as u64))
            .map_err(|e| refuse(format!("{}: {e}", log.display())))?;
    }
    Ok((driver, records))
}

/// What a resumed run must share with its checkpoint: the case, the scheme, the files and every
/// param in use, the step guard, the mesh, and the case's own settings (`more`).
pub fn identity(case: &str, in_use: &FilesInUse, mesh: &Mesh, more: &[(&str, String)]) -> Identity {
    let common = [
        ("case", case.to_string()),
        ("scheme", in_use.scheme_name().to_string()),
        ("contact law", in_use.forms.contact_name()),
        ("files run interpreted", in_use.interpreted().join(", ")),
        ("files compiled for the material", format!("{:?}", in_use.rebound())),
        ("step guard", format!("{:?}", in_use.guard)),
        ("mesh", mesh_fingerprint(mesh)),
    ];
    let forms = &in_use.forms;
    let values = forms.params.values().into_iter().chain(forms.body_values()).chain(forms.pair_values());
    let params = values.map(|(name, p)| (format!("param {name}"), format!("{:?}", p.value)));
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
            energy_dissipated: 0.0,
            energy_u0: vec![0.0, 1.0],
            energy_kinetic: 0.5,
            energy_growth: 0.0,
            energy_made: 0.25,
            energy_lowest: -1.5,
            energy_last: 2.0,
            energy_external: 0.5,
            energy_switches: vec![true],
            states: vec![vec![f64::NAN, -0.0, 1e-300], vec![f64::INFINITY, 2.0, 3.0]],
            periodic: true,
            adaptive: Some(crate::simulation::step_control::AdaptiveState {
                t: 0.3,
                controller: crate::simulation::step_control::Controller { h: 0.1, error: 0.5, rejected: true },
                steps: Default::default(),
                bracket: Some(0.35),
            }),
        }
    }

    fn ident(dt: &str) -> Identity {
        vec![("case".into(), "a_run".into()), ("dt".into(), dt.into())]
    }

    #[test]
    fn a_checkpoint_reads_back_bit_for_bit_and_refuses_another_run() {
        let dir = std::env::temp_dir().join(format!("signorini-checkpoint-{}", std::process::id()));
        let mut control = Control::new(3, Some(dir.clone()), ident("0.02"), false, None).unwrap();
        control.write(driver(), vec![7, 8, 9]).unwrap();
        control.write(driver(), vec![10]).unwrap();
        // A record appended by a run that crashed before its checkpoint.bin: cut on resume.
        std::fs::OpenOptions::new()
            .append(true)
            .open(dir.join(LOG))
            .and_then(|mut f| std::io::Write::write_all(&mut f, &[1, 0, 0, 0, 0, 0, 0, 0, 11]))
            .unwrap();
        let (d, o) = read(&dir, &ident("0.02"), None, true).unwrap();
        assert_eq!(std::fs::metadata(dir.join(LOG)).unwrap().len(), 8 + 3 + 8 + 1);
        let bits = |s: &DriverState| s.states.iter().flatten().map(|x| x.to_bits()).collect::<Vec<u64>>();
        assert_eq!(bits(&d), bits(&driver()));
        assert_eq!((d.steps_done, d.accepted, d.level, d.cuts, o), (3, 4, 1, 1, vec![vec![7, 8, 9], vec![10]]));
        let e = read(&dir, &ident("0.01"), None, true).unwrap_err().to_string();
        assert!(e.contains("written with dt 0.02; this run has dt 0.01"), "{e}");
        // A truncated file is refused, not half read.
        let path = dir.join(FILE);
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let e = read(&dir, &ident("0.02"), None, true).unwrap_err().to_string();
        assert!(e.contains("damaged or truncated"), "{e}");
        std::fs::write(&path, b"hello").unwrap();
        assert!(read(&dir, &ident("0.02"), None, true).unwrap_err().to_string().contains("not a signorini checkpoint"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_split_checkpoint_is_its_parts_and_any_run_reads_it_whole() {
        let dir = std::env::temp_dir().join(format!("signorini-checkpoint-parts-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        // Three nodes of two dofs: node 1 is rank 0's, nodes 0 and 2 rank 1's.
        let owner = vec![1, 0, 1];
        let process =
            |rank: usize, size: usize, owner: &[u32]| Some(Arc::new(Ownership::new(owner.to_vec(), 2, rank, size)));
        let mut state = driver();
        state.states = vec![(0..6).map(|i| i as f64 + 0.5).collect(), vec![f64::NAN, -0.0, 1e-300, 2.0, 3.0, 4.0]];
        state.energy_u0 = vec![6.0, 5.0, 4.0, 3.0, 2.0, 1.0];
        let bits = |v: &[Vec<f64>]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<u64>>();
        let write = |rank: usize, state: &DriverState| {
            let mut control =
                Control::new(3, Some(dir.clone()), ident("0.02"), false, process(rank, 2, &owner)).unwrap();
            control.write(state.clone(), vec![rank as u8]).unwrap();
        };
        write(1, &state);
        write(0, &state);
        for rank in 0..2 {
            assert!(dir.join(format!("checkpoint.{rank}.1.bin")).is_file(), "rank {rank}'s part");
        }
        // One process, or three split otherwise, reads every part and puts each row at its dof.
        let other = process(2, 3, &[0, 1, 2]);
        for split in [None, other.as_deref()] {
            let (d, o) = read(&dir, &ident("0.02"), split, false).unwrap();
            assert_eq!(bits(&d.states), bits(&state.states));
            assert_eq!(bits(&[d.energy_u0]), bits(&[state.energy_u0.clone()]));
            assert_eq!(o, vec![vec![0]]);
        }
        // The next checkpoint's parts go in the other slot: a crash before rank 0's manifest
        // leaves the last one readable.
        let mut next = state.clone();
        next.states[0][3] = 99.0;
        let mut control = Control::new(3, Some(dir.clone()), ident("0.02"), false, process(1, 2, &owner)).unwrap();
        control.write(state.clone(), vec![1]).unwrap();
        control.write(next, vec![1]).unwrap();
        assert!(dir.join("checkpoint.1.0.bin").is_file());
        let (d, _) = read(&dir, &ident("0.02"), None, false).unwrap();
        assert_eq!(bits(&d.states), bits(&state.states));
        // A missing part is refused by name.
        std::fs::remove_file(dir.join("checkpoint.0.1.bin")).unwrap();
        let e = read(&dir, &ident("0.02"), None, false).unwrap_err().to_string();
        assert!(e.contains("checkpoint.0.1.bin"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
