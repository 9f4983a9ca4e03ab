//! Any text is either a case or an error naming the file and line; nothing panics. Paths in
//! the case resolve against a directory that does not exist, so only library names load.
#![no_main]

use libfuzzer_sys::fuzz_target;
use signorini::cases::file;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = file::parse(text, std::path::Path::new("/nonexistent/fuzz/case.toml"));
    }
});
