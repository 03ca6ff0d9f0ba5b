//! The words of `/events`: `ricochet-record`'s, under the name the commands use.

#[allow(
    unused_imports,
    reason = "kept for the commands that word events; none of today's does"
)]
pub use ricochet_record::events::*;
