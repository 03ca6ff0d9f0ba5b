//! Coin Rush in a plain `GameLoop`, the game's own loop: a player runs right, jumps onto
//! the moving platform, rides it, jumps from it to the coin above it and scores; the coin
//! comes back `COIN_RESPAWN` frames later. The player is driven like a client would drive
//! it, from what it sees (its runner's and the platform's positions), not by a timed
//! script, and every expected value is the arena's geometry (`arena.rs`'s constants).

use ricochet_coin_rush::arena::{
    COIN, COIN_RADIUS, GRAVITY, JUMP_SPEED, PLATFORM_HALF, PLATFORM_START, RUNNER_HALF, TILE_HALF,
    platform_x,
};
use ricochet_coin_rush::{COIN_RESPAWN, COINS, CoinRush, Input, SPAWNS};
use ricochet_sim::prelude::*;

/// Exact sums of a few terms of size ~10 are within a few ulps of their rounded value.
const ROUNDING: f64 = 1e-9;

/// The coin above the platform (slot 2): reached only by a jump from the platform.
const HIGH_COIN: usize = 2;

fn run_input(run: f64) -> Input {
    Input {
        run: Some(run),
        ..Input::default()
    }
}

fn jump() -> Input {
    Input {
        jump: true,
        ..Input::default()
    }
}

#[test]
fn a_player_runs_right_jumps_onto_the_platform_and_picks_the_coin_above_it() {
    let (sim, game) = CoinRush::new().unwrap();
    let mut run = GameLoop::new(sim, game);
    let ada = run.join("ada").unwrap();
    let body = run.game().runner(ada).unwrap();
    let platform = run.game().platform();
    // The first player stands at the first spawn point.
    assert_eq!(run.sim().position(body), Some(SPAWNS[0]));

    // Where a runner stands on the platform, and how high a jump from the floor takes
    // its feet: 0.5 + v² / 2g (the continuous apex; a stepped one is lower).
    let on_platform = PLATFORM_START.y + PLATFORM_HALF.y + RUNNER_HALF.y;
    let floor_jump_feet = TILE_HALF + JUMP_SPEED * JUMP_SPEED / (2.0 * GRAVITY);
    let coin = COINS[HIGH_COIN];

    let mut rode = None;
    let mut picked = None;
    let mut held = 0.0;
    for _ in 0..1200 {
        let frame = run.frame();
        let p = run.sim().position(body).unwrap();
        let grounded = run.sim().grounded(body) == Some(true);
        let carried = run.sim().carrier(body) == Some(Some(platform));
        let px = run.sim().position(platform).unwrap().x;
        // Run at the platform until on it, then at the coin's x (staying on it); jump onto
        // the platform when its near edge is 0.5 to 2 units ahead, and from it when under
        // the coin (the platform's round trip brings it under the coin).
        let target = if picked.is_some() {
            p.x
        } else if carried {
            // Toward the coin, staying a runner's width inside the platform's ends.
            let reach = PLATFORM_HALF.x - RUNNER_HALF.x;
            coin.x.clamp(px - reach, px + reach)
        } else {
            px
        };
        let want: f64 = if (target - p.x).abs() < 0.1 {
            0.0
        } else {
            (target - p.x).signum()
        };
        if want != held {
            run.input(ada, run_input(want)).unwrap();
            held = want;
        }
        let gap = (px - p.x).abs() - PLATFORM_HALF.x - RUNNER_HALF.x;
        if picked.is_none() && grounded && !carried && (0.5..2.0).contains(&gap) {
            run.input(ada, jump()).unwrap();
        }
        if picked.is_none() && carried && grounded && (coin.x - p.x).abs() < 0.1 {
            run.input(ada, jump()).unwrap();
        }
        run.step().unwrap();
        if carried && rode.is_none() {
            rode = Some(frame);
            // Standing on the platform's top, wherever it is: its y is fixed.
            assert!(
                (p.y - on_platform).abs() < ROUNDING,
                "on the platform at y {}",
                p.y
            );
            let px_then = platform_x(frame.saturating_sub(1));
            assert!(
                (px - px_then).abs() < ROUNDING,
                "platform at {px}, expected {px_then}"
            );
        }
        let state = run.game().state().unwrap();
        if picked.is_none() && state.players[0].score == 1 {
            picked = Some(frame);
            let p = run.sim().position(body).unwrap();
            // The coin went, and it was the one above the platform: the runner's box is
            // within the coin's radius of it (closest point of the box to the centre).
            assert_eq!(state.coins, [true, true, false, true, true]);
            assert_eq!(run.game().coin(HIGH_COIN), None);
            let dx = ((coin.x - p.x).abs() - RUNNER_HALF.x).max(0.0);
            let dy = ((coin.y - p.y).abs() - RUNNER_HALF.y).max(0.0);
            assert!(
                (dx * dx + dy * dy).sqrt() <= COIN_RADIUS + ROUNDING,
                "runner at {p}"
            );
            // Higher than a jump from the floor reaches: it came from the platform.
            assert!(
                p.y - RUNNER_HALF.y > floor_jump_feet,
                "feet at {}",
                p.y - RUNNER_HALF.y
            );
            assert!(
                run.sim()
                    .overlap_point(coin, &QueryFilter::layers(&[COIN]))
                    .is_empty()
            );
        }
        if let Some(at) = picked
            && frame >= at + COIN_RESPAWN
        {
            break;
        }
    }
    let rode = rode.expect("the runner never stood on the platform");
    let picked = picked.expect("the runner never scored");
    assert!(rode < picked);
    // The coin is back in the frame COIN_RESPAWN after the pickup, where it was.
    let back = run.sim().overlap_point(coin, &QueryFilter::layers(&[COIN]));
    assert_eq!(back.len(), 1, "no coin at {coin}");
    assert_eq!(run.game().coin(HIGH_COIN), Some(back[0]));
    assert_eq!(run.frame(), picked + COIN_RESPAWN + 1);
    assert_eq!(run.game().state().unwrap().coins, [true; 5]);
}
