//! A problem's run and its checkpoints: what a checkpoint keeps of the run (the rows, stages and
//! snapshots since the one before) and what a resumed run must share with the run that wrote it.

use serde::{Deserialize, Serialize};

use super::options::{Options, Times};
use super::{ProblemFile, ProblemParam};
use crate::driver::FilesInUse;

/// What a checkpoint keeps of the run: what is new since the checkpoint before.
#[derive(Serialize, Deserialize)]
pub(super) struct Record {
    pub(super) series: Vec<(f64, Vec<f64>)>,
    pub(super) iterations: Vec<usize>,
    pub(super) switches: Vec<Vec<bool>>,
    pub(super) stages: Vec<(String, f64, Vec<f64>)>,
    pub(super) snapshots: Vec<(f64, String)>,
}

/// What a resumed run must share with its checkpoint.
pub(super) fn identity(
    opts: &Options,
    pf: &ProblemFile,
    params: &[ProblemParam],
    in_use: &FilesInUse,
    mesh: &crate::runtime::fem::mesh::Mesh,
    s: &Times,
) -> crate::checkpoint::Identity {
    let mut more = vec![
        ("problem file", format!("{} ({:016x})", pf.file, pf.text_hash)),
        ("mass", format!("{:?}", opts.mass)),
        ("cell size", format!("{:?}", opts.cell_size)),
        ("dt", format!("{:?}", s.dt)),
        ("t_start", format!("{:?}", s.t_start)),
        ("t_end", format!("{:?}", s.t_end)),
        ("adaptive steps", format!("{:?}", s.adaptive)),
        ("Newton options", format!("{:?}", opts.newton)),
        ("checkpoint period", opts.checkpoint_every.to_string()),
    ];
    let problem_params: Vec<String> = params.iter().map(|p| format!("{} = {:?}", p.name, p.value)).collect();
    more.push(("problem params", problem_params.join(", ")));
    crate::checkpoint::identity(pf.name(), in_use, mesh, &more)
}
