//! VTU snapshots of a run (displacement, velocity, the cells' von Mises stress) every K steps,
//! and their PVD collection for ParaView; a run split across processes writes one piece per
//! process and a PVTU file per snapshot.

use std::path::PathBuf;

use super::Operators;
use crate::error::CaseError;

/// VTU snapshots every `every` steps into `dir`/vtu, and the PVD collection of them.
pub struct Snapshots {
    dir: Option<PathBuf>,
    every: usize,
    name: String,
    written: Vec<(f64, String)>,
}

impl Snapshots {
    /// Writes nothing unless `out` is given and `every` > 0.
    pub fn new(out: Option<&PathBuf>, every: usize, name: &str) -> Snapshots {
        Snapshots { dir: out.filter(|_| every > 0).cloned(), every, name: name.to_string(), written: Vec::new() }
    }

    /// The displacement and velocity at step `k`, the cell-mean von Mises stress when the files
    /// in use provide it, and each cell's body. In a run split across processes each writes a piece (its cells),
    /// and rank 0 the PVTU file of the pieces: every process calls it, with the directory.
    pub fn write(&mut self, ops: &Operators, k: usize, t: f64, u: &[f64], v: &[f64]) -> Result<(), CaseError> {
        let Some(dir) = &self.dir else { return Ok(()) };
        if !k.is_multiple_of(self.every) {
            return Ok(());
        }
        let mesh = ops.asm.mesh();
        let vm = match (&ops.von_mises, &ops.cell_measure) {
            (Some(vm), Some(measure)) => {
                let size = measure.cell_values(ops.asm, &[], 0.0);
                vm.cell_values(ops.asm, &[u], 0.0).iter().zip(&size).map(|(v, a)| v / a).collect()
            }
            _ => vec![f64::NAN; mesh.num_cells()],
        };
        let d = mesh.dim();
        let point = [
            crate::vtu::Field { name: "displacement", components: d, values: u },
            crate::vtu::Field { name: "velocity", components: d, values: v },
        ];
        let owned = ops.asm.owned_cells();
        // Each cell's body, numbered from 0 in the problem's order (0 for one body).
        let body: Vec<f64> =
            (0..owned).map(|c| mesh.bodies.iter().position(|b| b.cells[c]).unwrap_or(0) as f64).collect();
        let cell = [
            crate::vtu::Field { name: "von_mises", components: 1, values: &vm[..owned] },
            crate::vtu::Field { name: "body", components: 1, values: &body },
        ];
        let base = format!("{}_{k:06}", self.name);
        let written = |path: &std::path::Path| {
            let path = path.display().to_string();
            move |source| CaseError::Write { path, source }
        };
        let file = match ops.asm.pattern().ownership() {
            None => {
                let file = format!("{base}.vtu");
                let path = dir.join("vtu").join(&file);
                crate::vtu::write(&path, mesh, &point, &cell).map_err(written(&path))?;
                file
            }
            // A split run: each process writes the cells it owns, rank 0 the file that joins them.
            Some(o) => {
                let piece = |rank: usize| format!("{base}_{rank}.vtu");
                let path = dir.join("vtu").join(piece(o.rank()));
                let cells: Vec<usize> = (0..owned).collect();
                crate::vtu::write_piece(&path, mesh, &cells, &point, &cell).map_err(written(&path))?;
                if o.rank() != 0 {
                    return Ok(());
                }
                let file = format!("{base}.pvtu");
                let path = dir.join("vtu").join(&file);
                let pieces: Vec<String> = (0..o.size()).map(piece).collect();
                crate::vtu::write_parallel(&path, d, &pieces, &point, &cell).map_err(written(&path))?;
                file
            }
        };
        self.written.push((t, format!("vtu/{file}")));
        Ok(())
    }

    /// The snapshots written so far: (time, file), for a checkpoint.
    pub fn written(&self) -> &[(f64, String)] {
        &self.written
    }

    /// Adds snapshots an earlier part of the run wrote.
    pub fn extend_written(&mut self, written: Vec<(f64, String)>) {
        self.written.extend(written);
    }

    /// Writes the collection `dir`/NAME.pvd (if any snapshot was written).
    pub fn finish(self) -> Result<(), CaseError> {
        let (Some(dir), false) = (&self.dir, self.written.is_empty()) else { return Ok(()) };
        let path = dir.join(format!("{}.pvd", self.name));
        crate::vtu::write_collection(&path, &self.written)
            .map_err(|source| CaseError::Write { path: path.display().to_string(), source })
    }
}
