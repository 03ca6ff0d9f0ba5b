//! Any text given to `ricochet collide` gives results or errors, never a panic, and no result
//! is NaN. See `ricochet_fuzz::checks::collide`.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Case files are read as UTF-8 text; other bytes never reach the parser.
    if let Ok(text) = std::str::from_utf8(data) {
        ricochet_fuzz::checks::collide(text);
    }
});
