//! Checkpoint and restart (issue 13): a run killed at arbitrary moments (or crashed around its
//! step cuts) and resumed from its periodic checkpoints writes the same series.csv, bit for bit,
//! as an uninterrupted run with the same checkpoint period; an interrupted run writes complete
//! outputs and exits with 130, keeping its last periodic checkpoint (bit for bit) or, without
//! periodic ones, writing one that resumes to round-off; a checkpoint of other options is
//! refused. A frictional law, whose previous level the checkpoint keeps, resumes bit for bit
//! too.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_signorini");
/// The coarse disc through its first contact (t ≈ 6.3) and rebound: 150 steps.
const RUN: [&str; 12] =
    ["run", "disc", "--h", "2", "--t-start", "5.5", "--t-end", "8.5", "--dt", "0.02", "--checkpoint-every", "13"];

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("signorini-checkpoint-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn spawn(args: &[&str]) -> Child {
    Command::new(BIN).args(args).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().expect("the binary starts")
}

fn finish(child: Child) -> (Option<i32>, String) {
    let out = child.wait_with_output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

fn series(dir: &Path) -> String {
    std::fs::read_to_string(dir.join("series.csv")).expect("series.csv")
}

/// A deterministic sequence of delays (a linear congruential generator).
struct Delays(u64);

impl Delays {
    fn next(&mut self, max_ms: u64) -> Duration {
        self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        Duration::from_millis(20 + (self.0 >> 33) % max_ms)
    }
}

#[test]
fn killed_and_resumed_discs_have_the_bits_of_an_uninterrupted_one() {
    kill_and_resume("disc", &RUN);
}

#[test]
fn killed_and_resumed_bars_have_the_bits_of_an_uninterrupted_one() {
    kill_and_resume("bar", &["run", "bar", "--ne", "100", "--dt", "0.002", "--checkpoint-every", "37"]);
}

/// A frictional law (`prev`: the slip since the previous level, which the checkpoint keeps),
/// run by path, under HHT, whose accepted level reads the level before it, and TR-BDF2.
#[test]
fn killed_and_resumed_frictional_discs_have_the_bits_of_an_uninterrupted_one() {
    let law = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/problems/coulomb_penalty.wf");
    for scheme in ["hht", "trbdf2"] {
        let mut args = RUN.to_vec();
        args.extend_from_slice(&["--contact", law, "--scheme", scheme]);
        kill_and_resume(&format!("coulomb-{scheme}"), &args);
    }
}

/// Running columns (`cumulative`, `initial`) are rebuilt from the rows the checkpoint kept.
#[test]
fn killed_and_resumed_oblique_discs_have_the_bits_of_an_uninterrupted_one() {
    let mut args = RUN.to_vec();
    args[1] = "oblique_disc";
    kill_and_resume("oblique", &args);
}

/// Runs `run` to the end; then again, killed at arbitrary moments and resumed from its
/// checkpoints until a resumption ends it: both series.csv must have the same bytes.
fn kill_and_resume(name: &str, run_args: &[&str]) {
    let root = scratch(name);
    let full = root.join("full");
    let clock = Instant::now();
    let (code, err) = finish(spawn(&[run_args, &["--out", full.to_str().unwrap()]].concat()));
    assert_eq!(code, Some(0), "{err}");
    let reference = series(&full);
    // Kill times spread over the run's length, whatever the machine's speed.
    let length = clock.elapsed().as_millis() as u64;
    let run = root.join("run");
    let run_s = run.to_str().unwrap();
    let mut delays = Delays(0x5eed);
    let (mut kills, mut resumed) = (0, 0);
    for attempt in 0.. {
        assert!(attempt < 80, "no run was killed and resumed in 80 attempts ({kills} kills)");
        let resume = run.join("checkpoint.bin").exists();
        let args: Vec<&str> = if resume {
            [run_args, &["--resume", run_s]].concat()
        } else {
            [&["--force"], run_args, &["--out", run_s]].concat()
        };
        let mut child = spawn(&args);
        if kills >= 3 && resume {
            // The last resumption runs to the end.
            let (code, err) = finish(child);
            assert_eq!(code, Some(0), "attempt {attempt} ({args:?}): {err}");
            resumed += 1;
            break;
        }
        std::thread::sleep(delays.next(length.max(40)));
        if child.try_wait().unwrap().is_none() {
            child.kill().unwrap();
            let _ = child.wait();
            kills += 1;
            resumed += resume as usize;
        } else {
            // It ended before the kill: start over.
            let _ = child.wait();
            let _ = std::fs::remove_dir_all(&run);
        }
    }
    assert!(series(&run) == reference, "series.csv after {kills} kills and {resumed} resumptions differs");
    // The last run did resume: it started after step 0.
    let summary = std::fs::read_to_string(run.join("summary.json")).unwrap();
    assert!(summary.contains("\"resumed\"") && summary.contains("\"bit_for_bit\": true"), "{summary}");
    eprintln!("{kills} kills, {resumed} resumptions");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn an_interrupted_run_keeps_its_last_periodic_checkpoint_and_resumes_bit_for_bit() {
    interrupt_and_resume("interrupt-periodic", "13", true);
}

#[test]
fn an_interrupted_run_without_periodic_checkpoints_writes_one_that_resumes_to_round_off() {
    interrupt_and_resume("interrupt-once", "0", false);
}

/// SIGINT once the run is stepping: exit 130 with complete outputs; then `--resume` completes
/// the run, with the bits of the uninterrupted one (`exact`) or to round-off.
fn interrupt_and_resume(name: &str, period: &str, exact: bool) {
    let root = scratch(name);
    let mut args: Vec<&str> = RUN.to_vec();
    args[11] = period;
    let full = root.join("full");
    let clock = Instant::now();
    let (code, err) = finish(spawn(&[&args[..], &["--out", full.to_str().unwrap()]].concat()));
    assert_eq!(code, Some(0), "{err}");
    let length = clock.elapsed();
    let run = root.join("run");
    let mut child = spawn(&[&args[..], &["--out", run.to_str().unwrap()]].concat());
    // Interrupt once the run is stepping: its first periodic checkpoint is written, or a third
    // of the uninterrupted run's time has passed.
    let start = Instant::now();
    while !(run.join("checkpoint.bin").exists() || (!exact && start.elapsed() > length / 3))
        && start.elapsed() < Duration::from_secs(60)
    {
        std::thread::sleep(Duration::from_millis(5));
    }
    // SAFETY: sending a signal to our own child.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    let status = child.wait().unwrap();
    if status.code() == Some(0) || !run.join("checkpoint.bin").exists() {
        eprintln!("the interrupt arrived before the first step or after the last: nothing to check");
        return;
    }
    assert_eq!(status.code(), Some(130));
    let rows = series(&run).lines().count();
    assert!(rows > 1 && rows <= series(&full).lines().count(), "{rows} rows after the interrupt");
    assert!(std::fs::read_to_string(run.join("summary.json")).unwrap().contains("interrupted"));
    let (code, err) = finish(spawn(&[&args[..], &["--resume", run.to_str().unwrap()]].concat()));
    assert_eq!(code, Some(0), "{err}");
    let (a, b) = (series(&full), series(&run));
    if exact {
        assert!(a == b, "series.csv differs after an interrupt and a resume from the periodic checkpoint");
        return;
    }
    assert_eq!(a.lines().count(), b.lines().count());
    for (x, y) in a.lines().zip(b.lines()).skip(1) {
        for (p, q) in x.split(',').zip(y.split(',')) {
            let (p, q): (f64, f64) = (p.parse().unwrap(), q.parse().unwrap());
            assert!((p - q).abs() <= 1e-9 * (1.0 + p.abs()), "{x}\n{y}");
        }
    }
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_checkpoint_of_other_options_is_refused() {
    let root = scratch("refuse");
    let run = root.join("run");
    let run_s = run.to_str().unwrap();
    let (code, err) = finish(spawn(&[&RUN[..], &["--out", run_s]].concat()));
    assert_eq!(code, Some(0), "{err}");
    let cases: [(&[&str], &str); 3] = [
        (&["--param", "gamma0=100"], "param gamma0 1000.0; this run has param gamma0 100.0"),
        (&["--scheme", "hht"], "scheme newmark; this run has scheme hht"),
        (&["--h", "1.5"], "mesh of"),
    ];
    for (extra, expected) in cases {
        let mut args: Vec<&str> = RUN.to_vec();
        if extra[0] == "--h" {
            args[3] = extra[1];
        } else {
            args.extend_from_slice(extra);
        }
        args.extend_from_slice(&["--resume", run_s]);
        let (code, err) = finish(spawn(&args));
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(err.contains("cannot resume") && err.contains(expected), "{args:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&root);
}

/// The disc through its first contact with γ0 = 1e13: Newton fails on some steps, which are
/// retried with Δt halved (where exactly depends on round-off, so the test finds them in an
/// uninterrupted run). Crashes right after accepted steps among the cut ones, then
/// resumptions: the step controller's state (halvings in force, streak) and the energy check
/// come back from the checkpoint, and the series has the bits of the uninterrupted run. (At
/// γ0 = 1e13 round-off in the contact rows gains E_aug 28 % of the energy scale: the guard's
/// tolerance is raised past it, its state still checkpointed.)
#[test]
fn restarts_through_step_cuts_have_the_bits_of_an_uninterrupted_run() {
    let root = scratch("cuts");
    let args = [
        "run",
        "disc",
        "--h",
        "2",
        "--t-start",
        "6",
        "--t-end",
        "7",
        "--param",
        "gamma0=1e13",
        "--checkpoint-every",
        "3",
        "--energy-tolerance",
        "1",
    ];
    let full = root.join("full");
    let (code, err) = finish(spawn(&[&args[..], &["--out", full.to_str().unwrap()]].concat()));
    assert_eq!(code, Some(0), "{err}");
    let cuts = |dir: &Path| -> usize {
        let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
        let at = summary.find("\"step_cuts\": ").expect("step_cuts") + 13;
        summary[at..].split(|c: char| !c.is_ascii_digit()).next().unwrap().parse().unwrap()
    };
    assert!(cuts(&full) >= 2, "the run should cut steps: {}", cuts(&full));
    // The accepted steps shorter than Δt = 0.02, and the one after each of them.
    let times: Vec<f64> =
        series(&full).lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect();
    let mut crashes: Vec<String> = Vec::new();
    for k in 1..times.len() {
        if (times[k] - times[k - 1] - 0.02).abs() > 1e-9 {
            for step in [k, k + 1] {
                if crashes.last().is_none_or(|c| c.parse::<usize>().unwrap() < step) && step < times.len() - 1 {
                    crashes.push(step.to_string());
                }
            }
        }
    }
    assert!(crashes.len() >= 2, "cut steps to crash at: {crashes:?}");
    let run = root.join("run");
    let run_s = run.to_str().unwrap();
    for (i, crash) in crashes.iter().take(4).enumerate() {
        let more: Vec<&str> = if i == 0 { vec!["--out", run_s] } else { vec!["--resume", run_s] };
        let status = Command::new(BIN)
            .args([&args[..], &more].concat())
            .env("SIGNORINI_CRASH_AFTER_STEP", crash.as_str())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .unwrap();
        assert!(!status.success(), "the run should have crashed after step {crash}");
    }
    let (code, err) = finish(spawn(&[&args[..], &["--resume", run_s]].concat()));
    assert_eq!(code, Some(0), "{err}");
    assert!(series(&run) == series(&full), "series.csv differs after crashes through the step cuts");
    assert_eq!(cuts(&run), cuts(&full));
    assert!(std::fs::read_to_string(run.join("summary.json")).unwrap().contains("\"resumed\""));
    let _ = std::fs::remove_dir_all(&root);
}

/// An adaptive run (issue 56): the checkpoint keeps the step controller (the time, the next
/// step, the last error, a pending event's bracket), so a resumed run takes the same steps.
#[test]
fn killed_and_resumed_adaptive_discs_have_the_bits_of_an_uninterrupted_one() {
    let mut args = RUN.to_vec();
    args.extend_from_slice(&["--adaptive", "1e-4"]);
    kill_and_resume("adaptive", &args);
}
