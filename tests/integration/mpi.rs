//! Runs under `mpirun` (feature `petsc`): the disc, the sphere and two discs of a problem of two
//! bodies through their first impact on 1, 2 and 3 processes agree with the serial direct run to 1e-8 of each column's scale; a run
//! resumed from its checkpoint (one part per process) on the same 2 processes has the bits of
//! the uninterrupted one, and on 3 or 1 agrees with it; a
//! split run's snapshots are pieces, one per process, that cover the mesh once; a process that
//! fails, alone or with the others, ends them all with its message; the commands
//! that run as one process refuse mpirun.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::petsc::{assert_agree, energy_scale, read_series};

const BIN: &str = env!("CARGO_BIN_EXE_signorini");

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-mpi-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// `mpirun` with `ranks` processes of `signorini ARGS` (several programs: `ARGS : ARGS`), its exit
/// status and stderr; killed (and failed) if it has not ended after `limit`.
fn mpirun(ranks: usize, args: &[&str], limit: Duration) -> (bool, String) {
    let mut command = Command::new("mpirun");
    command.args(["--allow-run-as-root", "--oversubscribe", "-n", &ranks.to_string(), BIN]);
    for a in args {
        // A second program of the launch: `: -n 1 signorini ...`.
        if *a == ":" {
            command.args([":", "-n", "1", BIN]);
        } else {
            command.arg(a);
        }
    }
    // One file per launch: the tests run at once.
    static LAUNCHES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let launch = LAUNCHES.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let stderr = std::env::temp_dir().join(format!("signorini-mpi-{}-{launch}.err", std::process::id()));
    let file = std::fs::File::create(&stderr).expect("a file for stderr");
    let mut child =
        command.stdout(Stdio::null()).stderr(file).spawn().expect("mpirun runs (apt-get install openmpi-bin)");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("mpirun's status") {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "mpirun -n {ranks} {args:?} still ran after {limit:?}: {}",
                std::fs::read_to_string(&stderr).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let text = std::fs::read_to_string(&stderr).unwrap_or_default();
    let _ = std::fs::remove_file(&stderr);
    (status.success(), text)
}

/// `signorini ARGS --solver direct --out DIR`, one process, which must succeed.
fn serial_direct(args: &[&str], dir: &std::path::Path) {
    let out =
        Command::new(BIN).args(args).args(["--solver", "direct", "--out"]).arg(dir).output().expect("the binary runs");
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// Every column of `run ARGS` on 1, 2 and 3 processes (PETSc's solvers) against the serial direct
/// run, to 1e-8 of the column's scale (`assert_agree`).
fn agree(args: &[&str], name: &str) {
    let root = scratch(name);
    let direct = root.join("direct");
    serial_direct(&[&["run"], args].concat(), &direct);
    let (header, reference) = read_series(&direct);
    for ranks in 1..=3 {
        let dir = root.join(format!("ranks-{ranks}"));
        let run: Vec<&str> = [&["run"], args, &["--solver", "petsc", "--out", dir.to_str().unwrap()]].concat();
        let (ok, err) = mpirun(ranks, &run, Duration::from_secs(600));
        assert!(ok, "{name} on {ranks} processes: {err}");
        let (_, rows) = read_series(&dir);
        assert_agree(&format!("{name} on {ranks} processes"), &header, &reference, &rows, energy_scale(&direct));
    }
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn the_disc_on_one_two_and_three_processes_agrees_with_the_serial_run() {
    agree(&["disc", "--t-start", "6", "--t-end", "8"], "disc");
}

/// Adaptive steps: every process takes the serial run's steps (the error and the contact set
/// are the same on each), so the rows line up.
#[test]
fn an_adaptive_disc_on_one_two_and_three_processes_agrees_with_the_serial_run() {
    agree(&["disc", "--t-start", "6", "--t-end", "8", "--adaptive", "1e-3"], "disc-adaptive");
}

#[test]
fn the_sphere_on_one_two_and_three_processes_agrees_with_the_serial_run() {
    agree(&["sphere", "--t-start", "6.3", "--t-end", "6.45"], "sphere");
}

#[test]
fn two_bodies_on_one_two_and_three_processes_agree_with_the_serial_run() {
    let problem = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/problems/two_discs.wf");
    agree(&[problem, "--t-end", "2.5"], "two_discs");
}

/// Two discs colliding through a contact pair, rubbing (±(1, 0.5), Coulomb's law between
/// them): every process keeps both surfaces whole and finds the facing points itself, and the
/// matrix couples the facing cells across processes. (Thrown head-on, their vertical velocity
/// is round-off of 1e-4 at most, below what an iterative solve is compared to.)
#[test]
fn two_colliding_bodies_on_one_two_and_three_processes_agree_with_the_serial_run() {
    let problem = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/problems/two_discs_collide.wf");
    let rubbing = ["--contact", "pair_penalty_coulomb", "--param", "w=0.5"];
    agree(&[&[problem][..], &rubbing, &["--t-start", "0.8", "--t-end", "3"]].concat(), "two_discs_collide");
}

/// A disc dropped on a block that stands on the ground: the ground's obstacle law and the
/// pair's law in one split run, through the impact.
#[test]
fn an_obstacle_beside_a_pair_on_one_two_and_three_processes_agrees_with_the_serial_run() {
    let problem = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/problems/disc_on_block_on_ground.wf");
    agree(&[problem, "--param", "drop=0.02", "--t-end", "0.4"], "disc_on_block_on_ground");
}

#[test]
fn a_run_resumed_on_the_same_two_processes_has_the_bits_of_an_uninterrupted_one() {
    let root = scratch("resume");
    let dir = root.join("run");
    let d = dir.to_str().unwrap();
    let run = ["run", "disc", "--t-start", "6", "--t-end", "8", "--checkpoint-every", "40"];
    let (ok, err) = mpirun(2, &[&run[..], &["--out", d]].concat(), Duration::from_secs(300));
    assert!(ok, "{err}");
    let full = std::fs::read(dir.join("series.csv")).expect("a series");
    // The checkpoint after step 80, the second: rank 0's manifest, and each process's rows in
    // the second slot of its own part.
    assert!(dir.join("checkpoint.bin").is_file(), "a checkpoint after step 80");
    for rank in 0..2 {
        assert!(dir.join(format!("checkpoint.{rank}.0.bin")).is_file(), "rank {rank}'s part of it");
    }
    let (_, reference) = read_series(&dir);
    // From the checkpoint after step 80: the last 20 steps again, on every process.
    let (ok, err) = mpirun(2, &[&run[..], &["--resume", d]].concat(), Duration::from_secs(300));
    assert!(ok, "{err}");
    assert!(std::fs::read(dir.join("series.csv")).expect("a series") == full, "the resumed series differs");
    // Three processes, split otherwise, and one read every part: the same run to round-off.
    for ranks in [3, 1] {
        let (ok, err) = mpirun(ranks, &[&run[..], &["--resume", d]].concat(), Duration::from_secs(300));
        assert!(ok, "resumed on {ranks}: {err}");
        let (header, rows) = read_series(&dir);
        let name = format!("the disc resumed on {ranks} processes");
        assert_agree(&name, &header, &reference, &rows, energy_scale(&dir));
    }
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_process_that_fails_alone_ends_every_process_with_its_message() {
    // The second process is given a problem that does not exist; the first runs on into its
    // first solve, where it would wait for the second forever.
    let args = ["run", "disc", "--t-start", "6", "--t-end", "8", ":", "run", "no_such_problem"];
    let (ok, err) = mpirun(1, &args, Duration::from_secs(120));
    assert!(!ok, "the launch failed");
    assert!(err.contains("error (rank 1 of 2)") && err.contains("no_such_problem"), "{err}");
}

#[test]
fn a_failure_on_every_process_ends_them_all_with_the_message() {
    // Two Krylov iterations cannot solve a step: Newton fails at every halving of the step.
    let args = ["run", "disc", "--t-start", "6", "--t-end", "6.2", "--petsc-options", "-ksp_max_it 2"];
    let (ok, err) = mpirun(2, &args, Duration::from_secs(300));
    assert!(!ok, "the run failed");
    assert!(err.contains("error (rank 0 of 2)") && err.contains("did not converge"), "{err}");
}

#[test]
fn commands_that_run_as_one_process_refuse_mpirun() {
    let dir = scratch("report");
    let (ok, err) = mpirun(2, &["report", "--quick", "--out", dir.to_str().unwrap()], Duration::from_secs(120));
    assert!(!ok, "report under mpirun failed");
    assert!(err.contains("`report` runs as one process"), "{err}");
    assert!(!dir.exists(), "nothing written");
}

/// A VTU file read back by an independent reader (vtkio): its points' coordinates and
/// displacements (3 per point), and its number of cells.
fn read_vtu(path: &std::path::Path) -> (Vec<f64>, Vec<f64>, usize) {
    use vtkio::model::{Attribute, DataSet, Piece};
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("not an unstructured grid") };
    let Piece::Inline(piece) = &pieces[0] else { panic!("piece not inline") };
    let points: Vec<f64> = piece.points.clone().cast_into().expect("points");
    let u = piece.data.point.iter().find_map(|a| match a {
        Attribute::DataArray(d) if d.name == "displacement" => d.data.clone().cast_into::<f64>(),
        _ => None,
    });
    (points, u.expect("a displacement"), piece.cells.types.len())
}

#[test]
fn a_split_run_writes_snapshots_as_pieces_that_cover_the_mesh_once() {
    let root = scratch("pieces");
    let (serial, split) = (root.join("serial"), root.join("split"));
    let run = ["run", "disc", "--t-start", "6.3", "--t-end", "6.5", "--vtu-every", "5"];
    serial_direct(&run, &serial);
    let (ok, err) = mpirun(
        3,
        &[&run[..], &["--solver", "petsc", "--out", split.to_str().unwrap()]].concat(),
        Duration::from_secs(300),
    );
    assert!(ok, "{err}");
    let pvd = std::fs::read_to_string(split.join("disc.pvd")).expect("a collection");
    for k in [0, 5, 10] {
        let file = format!("vtu/disc_{k:06}.pvtu");
        assert!(pvd.contains(&format!("file=\"{file}\"")), "the collection lists {file}: {pvd}");
        let pvtu = std::fs::read_to_string(split.join(&file)).expect("a parallel file");
        // Each node of the mesh, by its position, with its displacement.
        let by_node = |path: &std::path::Path| {
            let (points, u, cells) = read_vtu(path);
            let key = |x: &[f64]| format!("{:.9} {:.9}", x[0], x[1]);
            let nodes: std::collections::HashMap<String, Vec<f64>> =
                points.chunks(3).map(key).zip(u.chunks(3).map(<[f64]>::to_vec)).collect();
            (nodes, cells)
        };
        let (expected, whole_cells) = by_node(&serial.join(format!("vtu/disc_{k:06}.vtu")));
        let (mut seen, mut cells_seen) = (std::collections::HashMap::new(), 0);
        for rank in 0..3 {
            let piece = format!("disc_{k:06}_{rank}.vtu");
            assert!(pvtu.contains(&format!("Source=\"{piece}\"")), "{file} lists {piece}");
            let (nodes, cells) = by_node(&split.join("vtu").join(&piece));
            cells_seen += cells;
            seen.extend(nodes);
        }
        assert_eq!(cells_seen, whole_cells, "snapshot {k}: the pieces' cells are the mesh's, each once");
        assert_eq!(seen.len(), expected.len(), "snapshot {k}: every node in some piece");
        let scale = expected.values().flatten().fold(1e-300f64, |m, x| m.max(x.abs()));
        for (at, u) in &expected {
            let v = &seen[at];
            assert!(u.iter().zip(v).all(|(a, b)| (a - b).abs() <= 1e-8 * scale), "snapshot {k} at {at}: {u:?} {v:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&root);
}
