//! Ricochet's integration tests: one target, a module per area (ripgrep's layout). Tests that
//! need the real binary run it through [`util::ricochet`].

mod collide_cli;
mod collision_cases;
mod util;
