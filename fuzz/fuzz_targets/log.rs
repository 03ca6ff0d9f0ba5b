//! Any bytes read as a log (`ricochet diff`, `read_log`) give messages or an error, never a
//! panic: damaged summaries, chunks and footers included. See `ricochet_fuzz::checks::log`.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    ricochet_fuzz::checks::log(data);
});
