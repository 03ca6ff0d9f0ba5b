//! Ricochet's integration tests: one target, a module per area (ripgrep's layout). Tests that
//! need the real binary run it through [`util::ricochet`].

mod accuracy;
mod bad_scenarios;
mod bench_cli;
mod channel_schemas;
mod cluster_cli;
mod collide_cli;
mod collision_cases;
mod damaged_logs;
mod dump_cli;
mod fuzz_corpus;
mod golden;
mod hostile;
mod large_scenario;
mod run_cli;
mod scenario_limits;
mod seek;
mod serve_bounds;
mod serve_client;
mod serve_hostile;
mod serve_load;
mod serve_query;
mod serve_rooms;
mod serve_session;
mod serve_siege;
mod serve_ws;
mod stress;
mod suite_cli;
mod suite_files;
mod suite_hardening;
mod sweep_cli;
mod threads;
mod tiled;
mod touch_log;
mod util;
mod validate_cli;
