//! Any text given to the scenario loader gives a scenario or an error, never a panic; a
//! scenario that loads also steps without panicking. See `ricochet_fuzz::checks::scenario`.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Scenario files are read as UTF-8 text; other bytes never reach the parser.
    if let Ok(text) = std::str::from_utf8(data) {
        ricochet_fuzz::checks::scenario(text);
    }
});
