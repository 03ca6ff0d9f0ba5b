//! The simulation in a browser: the asteroids bench scene stepped through a few exported
//! functions, built for `wasm32-unknown-unknown` (no WASI, no bindings crate, no imports).
//! `scripts/browser-asteroids.mjs` loads it in Node as a page would and prints the gate's
//! text for the scene, which must equal the native program's block for `asteroids-200`.
//!
//! Build: `cargo build -p ricochet-portable --example browser_asteroids --target
//! wasm32-unknown-unknown` (with build-std, as the gate does).

use std::cell::RefCell;

use ricochet_sim::Simulation;

thread_local! {
    /// The page's one simulation (wasm32 without threads: one thread, so one slot).
    static SIM: RefCell<Option<Simulation>> = const { RefCell::new(None) };
}

/// Builds `asteroids-N` for `frames` frames (the bench scene, seeded) and returns its body
/// count, or 0 if `asteroids` is 0 or past the bench's cap.
#[unsafe(no_mangle)]
#[expect(
    unsafe_code,
    reason = "an export needs its unmangled name; no unsafe block"
)]
pub extern "C" fn asteroids_new(asteroids: u32, frames: u32) -> u32 {
    let n = asteroids as usize;
    if n == 0 || n > ricochet_scenes::bench::MAX_COUNT {
        return 0;
    }
    let sim = Simulation::new(&ricochet_scenes::bench::asteroids(n, u64::from(frames)));
    let bodies = sim.world().len() as u32;
    SIM.with(|s| *s.borrow_mut() = Some(sim));
    bodies
}

/// Steps one frame (the first step is frame 0, the initial state) and returns the frame's
/// number, or `u64::MAX` before [`asteroids_new`].
#[unsafe(no_mangle)]
#[expect(
    unsafe_code,
    reason = "an export needs its unmangled name; no unsafe block"
)]
pub extern "C" fn step() -> u64 {
    SIM.with(|s| {
        s.borrow_mut()
            .as_mut()
            .map_or(u64::MAX, |sim| sim.step().frame)
    })
}

/// The simulation's checksum (`Simulation::checksum`), 0 before [`asteroids_new`].
#[unsafe(no_mangle)]
#[expect(
    unsafe_code,
    reason = "an export needs its unmangled name; no unsafe block"
)]
pub extern "C" fn checksum() -> u64 {
    SIM.with(|s| s.borrow().as_ref().map_or(0, Simulation::checksum))
}

/// The world's digest (`World::digest`), 0 before [`asteroids_new`].
#[unsafe(no_mangle)]
#[expect(
    unsafe_code,
    reason = "an export needs its unmangled name; no unsafe block"
)]
pub extern "C" fn digest() -> u64 {
    SIM.with(|s| s.borrow().as_ref().map_or(0, |sim| sim.world().digest()))
}

/// The world's body count, 0 before [`asteroids_new`].
#[unsafe(no_mangle)]
#[expect(
    unsafe_code,
    reason = "an export needs its unmangled name; no unsafe block"
)]
pub extern "C" fn bodies() -> u32 {
    SIM.with(|s| {
        s.borrow()
            .as_ref()
            .map_or(0, |sim| sim.world().len() as u32)
    })
}
