//! The recorder: `ricochet-record`'s (`Recorder`, `LIBRARY`, `scene`, ...), under the name
//! the commands use.

pub use ricochet_record::*;
