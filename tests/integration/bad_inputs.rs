//! The bad-input corpus (`tests/bad_inputs/`, issue 13 item 10): every case runs the binary
//! with a timeout and must end with its expected exit status and message, never with a panic,
//! a crash or a hang. All failures are collected and reported together.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde::Deserialize;

/// A case that runs longer is killed and counted as a hang.
const TIMEOUT: Duration = Duration::from_secs(60);

#[derive(Deserialize)]
struct Corpus {
    case: Vec<Case>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    name: String,
    /// `{dir}`: the corpus directory; `{out}`: a fresh output directory of this case.
    args: Vec<String>,
    /// 0 only for borderline inputs whose result `expect` checks.
    exit: i32,
    /// Substrings of stderr (exit ≠ 0) or of stdout and stderr (exit 0).
    expect: Vec<String>,
    /// Substrings that must not appear (meaningless output of a run that should have stopped).
    #[serde(default)]
    reject: Vec<String>,
    /// The correct outcome is not yet the actual one: reported, not failed.
    known_failure: Option<String>,
}

struct Outcome {
    status: Option<i32>,
    signal: Option<i32>,
    stdout: String,
    stderr: String,
    hung: bool,
    seconds: f64,
}

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs")
}

/// Runs one case in a scratch directory of its own (cwd too: default outputs land there);
/// output goes to files so that a chatty child cannot block on a full pipe.
fn execute(case: &Case, scratch: &Path) -> Outcome {
    std::fs::create_dir_all(scratch).expect("scratch directory");
    let dir = corpus_dir();
    let out = scratch.join("out");
    let args: Vec<String> = case
        .args
        .iter()
        .map(|a| a.replace("{dir}", &dir.display().to_string()).replace("{out}", &out.display().to_string()))
        .collect();
    let (so, se) = (scratch.join("stdout"), scratch.join("stderr"));
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_signorini"))
        .args(&args)
        .current_dir(scratch)
        .env_remove("RUST_BACKTRACE")
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&so).expect("stdout file"))
        .stderr(std::fs::File::create(&se).expect("stderr file"))
        .spawn()
        .expect("spawn signorini");
    let mut hung = false;
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if start.elapsed() > TIMEOUT {
            hung = true;
            let _ = child.kill();
            break child.wait().expect("wait after kill");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let read = |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap_or_default()).into_owned();
    #[cfg(unix)]
    let signal = std::os::unix::process::ExitStatusExt::signal(&status);
    #[cfg(not(unix))]
    let signal = None;
    Outcome {
        status: status.code(),
        signal,
        stdout: read(&so),
        stderr: read(&se),
        hung,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// What is wrong with an outcome (empty: the case passes).
fn judge(case: &Case, o: &Outcome) -> Vec<String> {
    let mut wrong = Vec::new();
    if o.hung {
        wrong.push(format!("hang: killed after {} s", TIMEOUT.as_secs()));
    }
    if let Some(s) = o.signal {
        wrong.push(format!("crash: killed by signal {s}"));
    }
    if o.status == Some(101) {
        wrong.push("panic: exit status 101".into());
    }
    for bad in ["panicked", "RUST_BACKTRACE"] {
        if o.stderr.contains(bad) {
            wrong.push(format!("panic: stderr contains `{bad}`"));
        }
    }
    if !o.hung && o.signal.is_none() && o.status != Some(case.exit) {
        wrong.push(format!("exit status {:?}, expected {}", o.status, case.exit));
    }
    let text = if case.exit == 0 { format!("{}\n{}", o.stdout, o.stderr) } else { o.stderr.clone() };
    for want in &case.expect {
        if !text.contains(want.as_str()) {
            wrong.push(format!("missing `{want}`"));
        }
    }
    for unwanted in &case.reject {
        if text.contains(unwanted.as_str()) {
            wrong.push(format!("unexpected `{unwanted}`"));
        }
    }
    wrong
}

fn tail(s: &str) -> String {
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(15)..].join("\n      ")
}

#[test]
fn bad_inputs() {
    let text = std::fs::read_to_string(corpus_dir().join("cases.toml")).expect("cases.toml");
    let corpus: Corpus = match toml::from_str(&text) {
        Ok(corpus) => corpus,
        Err(e) => panic!("tests/bad_inputs/cases.toml: {e}"),
    };
    let mut names = std::collections::HashSet::new();
    for c in &corpus.case {
        assert!(names.insert(c.name.as_str()), "case name `{}` is repeated", c.name);
        assert!(!c.expect.is_empty(), "case `{}` expects nothing", c.name);
        assert!((0..=2).contains(&c.exit), "case `{}`: exit must be 0, 1 or 2", c.name);
    }
    let root = std::env::temp_dir().join(format!("signorini-bad-inputs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    // A few cases at a time: most are instant, the runs take a second or two.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get()).clamp(2, 4);
    let mut results: Vec<(usize, Outcome)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                s.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(case) = corpus.case.get(i) else { break done };
                        done.push((i, execute(case, &root.join(&case.name))));
                    }
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("worker")).collect()
    });
    results.sort_by_key(|(i, _)| *i);
    let mut failures = Vec::new();
    let mut known = Vec::new();
    let mut fixed = Vec::new();
    for (i, o) in &results {
        let case = &corpus.case[*i];
        let wrong = judge(case, o);
        match (&case.known_failure, wrong.is_empty()) {
            (Some(why), false) => known.push(format!("{} ({why}): {}", case.name, wrong.join("; "))),
            (Some(_), true) => fixed.push(case.name.clone()),
            (None, false) => failures.push(format!(
                "{} [{:.1} s]: {}\n    args: {:?}\n    status: {:?}\n    stdout:\n      {}\n    stderr:\n      {}",
                case.name,
                o.seconds,
                wrong.join("; "),
                case.args,
                o.status,
                tail(&o.stdout),
                tail(&o.stderr)
            )),
            (None, true) => {}
        }
    }
    let slowest = results.iter().max_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds));
    if let Some((i, o)) = slowest {
        eprintln!("{} cases; slowest: {} ({:.1} s)", results.len(), corpus.case[*i].name, o.seconds);
    }
    for k in &known {
        eprintln!("known failure: {k}");
    }
    let _ = std::fs::remove_dir_all(&root);
    assert!(fixed.is_empty(), "cases marked known_failure now pass (remove the mark): {}", fixed.join(", "));
    assert!(failures.is_empty(), "{} of {} cases failed:\n\n{}", failures.len(), results.len(), failures.join("\n\n"));
}
