//! `verify`: the library's claims measured, or with `--scheme` one scheme's file against what
//! it claims (exit 1 when a measurement contradicts a claim).

use std::path::Path;
use std::process::ExitCode;

use super::args::MethodArgs;
use super::fail;

/// Every measurement of `signorini verify`, written to `out`.
pub(super) fn library(out: &Path) -> ExitCode {
    match crate::verify::run(&mut |what| eprintln!("running {what}")) {
        Ok(v) => match v.write(out) {
            Ok(()) => {
                print!("{}", v.markdown());
                println!("wrote {}", out.join("verify.md").display());
                ExitCode::SUCCESS
            }
            Err(e) => fail(e),
        },
        Err(e) => fail(e),
    }
}

pub(super) fn scheme(out: &Path, args: &MethodArgs) -> ExitCode {
    let methods = match args.to_methods() {
        Ok(s) => s,
        Err(e) => return fail(e),
    };
    let v = match crate::verify::scheme::run(&methods, &mut |what| eprintln!("running {what}")) {
        Ok(v) => v,
        Err(e) => return fail(e),
    };
    if let Err(e) = v.write(out) {
        return fail(e);
    }
    print!("{}", v.markdown());
    println!("wrote {}", out.join(format!("verify_{}.md", v.scheme)).display());
    let contradicted: Vec<String> = v
        .verdicts
        .iter()
        .filter(|c| !c.holds)
        .map(|c| format!("{} = {} (measured {:.4})", c.claim, c.claimed, c.measured))
        .collect();
    if contradicted.is_empty() {
        ExitCode::SUCCESS
    } else {
        fail(format!("the measurements contradict what {}'s file claims: {}", v.scheme, contradicted.join(", ")))
    }
}
