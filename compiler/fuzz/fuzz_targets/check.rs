//! Any input either checks (and then generates parseable code) or yields diagnostics; nothing
//! panics. Imports resolve against an empty in-memory file system.
#![no_main]

use libfuzzer_sys::fuzz_target;
use signorini_compiler::{MemLoader, codegen, compile_text};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(compiled) = compile_text(std::path::Path::new("fuzz.wf"), &text, &MemLoader::default()) {
        let opts = codegen::Options { runtime: "::rt".into(), module: "fuzz".into(), source_name: "fuzz.wf".into() };
        compiled.rust(&opts).expect("valid input generates parseable code");
    }
});
