//! A split run's checkpoint (`mpirun`, each process owning some nodes): each process writes the
//! rows it owns of every state in `checkpoint.RANK.SLOT.bin`, with their dof numbers; rank 0's
//! `checkpoint.bin` is the manifest, which names the processes, the partition and the
//! checkpoint's generation. The parts go in two slots, by the generation's parity: a crash
//! after some processes wrote their parts and before rank 0 wrote the manifest leaves the
//! manifest's own slot whole.
//!
//! A run on as many processes with the same partition reads its own part only, and the
//! processes then exchange their rows; any other run (another number of processes, one process)
//! reads every part and places each value at its dof.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::runtime::linalg::ownership::Ownership;
use crate::runtime::linalg::pattern::Owners;

const MAGIC: &[u8; 8] = b"SIGNPART";
const FORMAT: u32 = 1;

/// What the manifest says of a split checkpoint's parts.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct Layout {
    pub(super) processes: u32,
    /// The partition's hash (`Ownership::fingerprint`).
    pub(super) partition: u64,
    /// Checkpoints written so far: the parts are in slot `generation % 2`.
    pub(super) generation: u64,
}

/// One process's rows of the run's states.
#[derive(Serialize, Deserialize)]
struct Part {
    program: String,
    generation: u64,
    rank: u32,
    processes: u32,
    /// The dofs this process owns, increasing; the rows below are theirs, in this order.
    dofs: Vec<u32>,
    states: Vec<Vec<f64>>,
    /// The energy check's u(0).
    u0: Vec<f64>,
}

/// Whole vectors: the scheme's states and the energy check's u(0).
pub(super) type Whole = (Vec<Vec<f64>>, Vec<f64>);

pub(super) fn path(dir: &Path, rank: u32, generation: u64) -> PathBuf {
    dir.join(format!("checkpoint.{rank}.{}.bin", generation % 2))
}

/// The manifest's record of this run's parts.
pub(super) fn layout(o: &Ownership, generation: u64) -> Layout {
    Layout { processes: o.size() as u32, partition: o.fingerprint(), generation }
}

/// Writes this process's rows of `states` and `u0` into its part of checkpoint `generation`,
/// atomically.
pub(super) fn write(dir: &Path, o: &Ownership, generation: u64, states: &[Vec<f64>], u0: &[f64]) -> Result<(), String> {
    let mine = o.mine();
    let rows = |v: &[f64]| mine.iter().map(|&i| v[i as usize]).collect::<Vec<f64>>();
    let part = Part {
        program: super::program(),
        generation,
        rank: o.rank() as u32,
        processes: o.size() as u32,
        dofs: mine.to_vec(),
        states: states.iter().map(|s| rows(s)).collect(),
        u0: rows(u0),
    };
    let bytes = super::encode(&part, MAGIC, FORMAT).map_err(|e| e.to_string())?;
    let path = path(dir, part.rank, generation);
    crate::output::write_atomic(&path, &bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The whole states of the checkpoint the manifest describes (`layout`), for a run split by
/// `this` (None: a run of one process, or one every process repeats). Collective when the run
/// has the checkpoint's processes and partition: each reads its own part, then they exchange.
pub(super) fn read(dir: &Path, layout: &Layout, this: Option<&Ownership>) -> Result<Whole, String> {
    let same = this.filter(|o| o.size() as u32 == layout.processes && o.fingerprint() == layout.partition);
    if let Some(o) = same {
        let part = read_part(dir, layout, o.rank() as u32)?;
        if part.dofs != o.mine() {
            return Err(format!(
                "{}: its rows are not the ones this process owns",
                path(dir, o.rank() as u32, layout.generation).display()
            ));
        }
        let n = o.owners().len() * o.dim();
        let whole = |rows: &[f64]| {
            let mut v = vec![0.0; n];
            part.dofs.iter().zip(rows).for_each(|(&i, &x)| v[i as usize] = x);
            o.complete(&mut v);
            v
        };
        let states = part.states.iter().map(|s| whole(s)).collect();
        return Ok((states, whole(&part.u0)));
    }
    if layout.processes == 0 {
        return Err("the manifest names no process".into());
    }
    let parts: Vec<Part> = (0..layout.processes).map(|r| read_part(dir, layout, r)).collect::<Result<_, _>>()?;
    let n: usize = parts.iter().map(|p| p.dofs.len()).sum();
    let count = parts[0].states.len();
    let (mut states, mut u0) = (vec![vec![0.0; n]; count], vec![0.0; n]);
    let mut seen = vec![false; n];
    for (r, part) in parts.iter().enumerate() {
        let at = path(dir, r as u32, layout.generation);
        if part.states.len() != count {
            return Err(format!("{}: {} states, where rank 0's part has {count}", at.display(), part.states.len()));
        }
        for (k, &i) in part.dofs.iter().enumerate() {
            let i = i as usize;
            if i >= n || std::mem::replace(&mut seen[i], true) {
                return Err(format!("{}: dof {i} is out of range or held by two parts", at.display()));
            }
            states.iter_mut().zip(&part.states).for_each(|(s, rows)| s[i] = rows[k]);
            u0[i] = part.u0[k];
        }
    }
    Ok((states, u0))
}

/// Process `rank`'s part, checked against the manifest.
fn read_part(dir: &Path, layout: &Layout, rank: u32) -> Result<Part, String> {
    use crate::runtime::input::{MAX_CHECKPOINT_BYTES, read_bounded};
    let path = path(dir, rank, layout.generation);
    let refuse = |why: String| format!("{}: {why}", path.display());
    let bytes = read_bounded(&path, MAX_CHECKPOINT_BYTES, "checkpoint part").map_err(|e| refuse(e.to_string()))?;
    let part: Part = super::decode(&bytes, MAGIC, FORMAT, "a part of a signorini checkpoint").map_err(refuse)?;
    if part.program != super::program() {
        return Err(refuse(format!("it was written by {}; this is {}", part.program, super::program())));
    }
    if (part.rank, part.processes, part.generation) != (rank, layout.processes, layout.generation) {
        return Err(refuse(format!(
            "it is rank {}'s of {} processes at checkpoint {}, where the manifest wants rank {rank}'s of {} at checkpoint {}",
            part.rank, part.processes, part.generation, layout.processes, layout.generation
        )));
    }
    let rows = part.dofs.len();
    if part.u0.len() != rows || part.states.iter().any(|s| s.len() != rows) {
        return Err(refuse("its states do not have a row per dof".into()));
    }
    Ok(part)
}
