//! A problem's params as options of `run`: `run bar --ne 40` is `run bar --param ne=40`, for
//! every param the problem's file declares (an option of `run` of the same name keeps its
//! meaning). The command line is rewritten so before clap reads it.

use super::Cli;

/// `run PROBLEM --NAME VALUE` for a param NAME of the problem (`--ne 40`, `--h 0.5`): as
/// `--param NAME=VALUE`. The problem's file declares its params; an option of `run` of the same
/// name keeps its meaning.
pub(super) fn as_options(mut args: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    let text = |a: &std::ffi::OsString| a.to_str().map(str::to_string);
    let Some(run) = args.iter().position(|a| a == "run") else { return args };
    let cmd = <Cli as clap::CommandFactory>::command();
    // The options of `run`, and whether each takes a value.
    let known: Vec<(String, bool)> = cmd
        .find_subcommand("run")
        .map(|r| {
            r.get_arguments()
                .filter_map(|a| a.get_long().map(|l| (l.to_string(), a.get_action().takes_values())))
                .collect()
        })
        .unwrap_or_default();
    let takes_value = |flag: &str| known.iter().find(|(l, _)| l == flag).map(|(_, v)| *v);
    // The problem: the first word after `run` that is no option's (an unknown option, maybe a
    // param of the problem, takes the word after it).
    let mut i = run + 1;
    let problem = loop {
        let Some(arg) = args.get(i).and_then(text) else { return args };
        match arg.strip_prefix("--") {
            Some("") => return args,
            Some(flag) if flag.contains('=') => i += 1,
            Some(flag) => i += if takes_value(flag) == Some(false) { 1 } else { 2 },
            None if arg.starts_with('-') => i += 1,
            None => break arg,
        }
    };
    if problem.ends_with(".toml") {
        return args;
    }
    let Ok(pf) = crate::problem::load(&problem) else { return args };
    let params: Vec<String> = pf.problem().params.iter().map(|q| q.name.name.clone()).collect();
    let mut i = run + 1;
    while i < args.len() {
        let Some(arg) = text(&args[i]) else {
            i += 1;
            continue;
        };
        if arg == "--" {
            break;
        }
        let Some(flag) = arg.strip_prefix("--") else {
            i += 1;
            continue;
        };
        let (name, inline) = match flag.split_once('=') {
            Some((n, v)) => (n.to_string(), Some(v.to_string())),
            None => (flag.to_string(), None),
        };
        let param = name.replace('-', "_");
        if takes_value(&name).is_some() || !params.contains(&param) {
            i += 1;
            continue;
        }
        let value = match inline {
            Some(v) => v,
            None if i + 1 < args.len() => text(&args.remove(i + 1)).unwrap_or_default(),
            None => {
                i += 1;
                continue;
            }
        };
        args[i] = "--param".into();
        args.insert(i + 1, format!("{param}={value}").into());
        i += 2;
    }
    args
}
