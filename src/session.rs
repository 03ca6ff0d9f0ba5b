//! Sessions (a simulation stepped with inputs, each recorded on `/input`):
//! `ricochet-record`'s, under the name the commands use.

pub use ricochet_record::session::*;
