//! Which channels a run records: `ricochet-record`'s, under the name the commands use.

pub use ricochet_record::channels::*;
