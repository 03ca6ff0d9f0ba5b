//! What Coin Rush refuses, by name, and that a refused input changes nothing; what a join
//! past the room's size gets; a zap's hit from the geometry of two runners on the floor.

use ricochet_coin_rush::{CoinRush, Input, MAX_PLAYERS, SPAWNS, STUN_FRAMES, ZAP_WINDOW, Zap};
use ricochet_sim::prelude::*;

fn started() -> GameLoop<CoinRush> {
    let (sim, game) = CoinRush::new().unwrap();
    let mut run = GameLoop::new(sim, game);
    run.join("ada").unwrap();
    run.join("bob").unwrap();
    run.step().unwrap(); // frame 0
    run
}

fn zap(dir: [f64; 2], seen: u64) -> Input {
    Input {
        zap: Some(Zap { dir, seen }),
        ..Input::default()
    }
}

fn refusal(run: &mut GameLoop<CoinRush>, player: Player, input: Input) -> String {
    let before = run.sim().checksum();
    let why = run.input(player, input).unwrap_err();
    // Nothing queued, nothing stunned: the next step is the step without it.
    assert_eq!(run.sim().checksum(), before, "{why}");
    why
}

#[test]
fn bad_inputs_are_refused_by_field_and_change_nothing() {
    let mut run = started();
    let ada = Player(1);
    let why = refusal(
        &mut run,
        ada,
        Input {
            run: Some(1.5),
            jump: true,
            zap: None,
        },
    );
    assert!(why.starts_with("run: from -1 to 1"), "{why}");
    let why = refusal(&mut run, ada, zap([0.0, 0.0], 0));
    assert!(why.starts_with("zap.dir:"), "{why}");
    let why = refusal(&mut run, ada, zap([f64::NAN, 1.0], 0));
    assert!(why.starts_with("zap.dir:"), "{why}");
    // The world holds the end of frame 0: frame 1 has not been seen by anyone.
    let why = refusal(&mut run, ada, zap([1.0, 0.0], 1));
    assert!(why.starts_with("zap.seen: frame 1"), "{why}");
    let why = refusal(&mut run, Player::HOST, Input::default());
    assert!(why.contains("has no runner"), "{why}");
    // A whole input is refused with its run: ada still stands at her spawn point.
    run.step().unwrap();
    let ada_body = run.game().runner(ada).unwrap();
    assert_eq!(run.sim().position(ada_body).unwrap().x, SPAWNS[0].x);
    assert!(!run.game().state().unwrap().players[0].stunned);
}

#[test]
fn a_zap_may_name_only_the_last_frames() {
    let mut run = started();
    for _ in 0..ZAP_WINDOW + 5 {
        run.step().unwrap();
    }
    let now = run.frame() - 1;
    let oldest = now + 1 - ZAP_WINDOW;
    let why = refusal(&mut run, Player(1), zap([1.0, 0.0], oldest - 1));
    assert!(
        why.starts_with(&format!(
            "zap.seen: frame {} is not one of the last {ZAP_WINDOW} ({oldest} to {now})",
            oldest - 1
        )),
        "{why}"
    );
    run.input(Player(1), zap([1.0, 0.0], oldest)).unwrap();
}

#[test]
fn a_zap_along_the_floor_stuns_the_runner_it_meets_for_a_second() {
    // Ada at x = -4, bob at x = 4, both on the floor at y = 1: a zap from ada to the right
    // meets bob's left face at 4 - 0.4 (nothing else at y = 1 between them).
    let mut run = started();
    let (ada, bob) = (Player(1), Player(2));
    let seen = run.frame() - 1;
    run.input(ada, zap([2.0, 0.0], seen)).unwrap();
    // Bob asks to run: stunned, he stays put for STUN_FRAMES frames, then runs.
    run.input(
        bob,
        Input {
            run: Some(1.0),
            ..Input::default()
        },
    )
    .unwrap();
    let bob_body = run.game().runner(bob).unwrap();
    let zapped = run.frame();
    for k in 0..STUN_FRAMES {
        if k == 1 {
            // Again, within ZAP_COOLDOWN: nothing (else the stun would end a frame later).
            let seen = run.frame() - 1;
            run.input(ada, zap([1.0, 0.0], seen)).unwrap();
        }
        run.step().unwrap();
        let s = run.game().state().unwrap();
        assert!(s.players[1].stunned, "frame {}", s.frame);
        assert_eq!(run.sim().position(bob_body).unwrap().x, SPAWNS[1].x);
    }
    run.step().unwrap();
    let s = run.game().state().unwrap();
    assert_eq!(s.frame, zapped + STUN_FRAMES);
    assert!(!s.players[1].stunned);
    // Running again from the frame the stun ends: 6 units/s, 0.1 a frame.
    let x = run.sim().position(bob_body).unwrap().x;
    assert!((x - (SPAWNS[1].x + 0.1)).abs() < 1e-12, "bob at {x}");
    // A zap the other way meets the left wall (its face at x = -16.5), no runner.
    let seen = run.frame() - 1;
    run.input(ada, zap([-1.0, 0.0], seen)).unwrap();
    run.step().unwrap();
    assert!(
        run.game()
            .state()
            .unwrap()
            .players
            .iter()
            .all(|p| !p.stunned)
    );
}

#[test]
fn a_full_room_refuses_a_join() {
    let (sim, game) = CoinRush::new().unwrap();
    let mut run = GameLoop::new(sim, game);
    for k in 0..MAX_PLAYERS {
        run.join(&format!("p{k}")).unwrap();
    }
    let (player, why) = run.join("late").unwrap_err();
    assert_eq!(player, Player(MAX_PLAYERS as u32 + 1));
    assert!(why.contains("full"), "{why}");
    // A leave frees a place; the runner is gone from the world.
    let body = run.game().runner(Player(1)).unwrap();
    run.leave(Player(1)).unwrap();
    assert!(!run.sim().contains(body));
    run.join("later").unwrap();
}

/// Bob jumps; ten frames later his feet are over 2 units up (15 units/s against 30: about
/// 15/6 - 15/36 ≈ 2.1), above a ray along y = 1 from ada. A zap naming the frame before his
/// jump, when he stood in its path, stuns him (lag compensation: the world as ada saw it);
/// one naming the last frame misses him.
#[test]
fn a_zap_is_checked_against_the_frame_its_player_saw() {
    let stunned_by = |seen_before_jump: bool| {
        let mut run = started();
        let (ada, bob) = (Player(1), Player(2));
        while run.frame() < 5 {
            run.step().unwrap();
        }
        let before_jump = run.frame() - 1;
        run.input(
            bob,
            Input {
                jump: true,
                ..Input::default()
            },
        )
        .unwrap();
        for _ in 0..10 {
            run.step().unwrap();
        }
        let bob_body = run.game().runner(bob).unwrap();
        let feet = run.sim().position(bob_body).unwrap().y - 0.5;
        assert!(feet > 1.5, "bob's feet at {feet}: still in the ray's way");
        let seen = if seen_before_jump {
            before_jump
        } else {
            run.frame() - 1
        };
        run.input(ada, zap([1.0, 0.0], seen)).unwrap();
        run.step().unwrap();
        run.game().state().unwrap().players[1].stunned
    };
    assert!(stunned_by(true), "a zap at the frame ada saw missed bob");
    assert!(
        !stunned_by(false),
        "a zap at the last frame hit bob in the air"
    );
}

/// The schemas sent to clients are JSON, and name what the game parses.
#[test]
fn the_schemas_are_json_and_name_the_fields() {
    let input: serde_json::Value = serde_json::from_str(ricochet_coin_rush::INPUT_SCHEMA).unwrap();
    let fields: Vec<&String> = input["properties"].as_object().unwrap().keys().collect();
    assert_eq!(fields, ["jump", "run", "zap"]);
    // Every field it names parses; one it does not is refused by name.
    let ok: Input =
        serde_json::from_str(r#"{"run": 1, "jump": true, "zap": {"dir": [1, 0], "seen": 3}}"#)
            .unwrap();
    assert_eq!(ok.run, Some(1.0));
    let bad = serde_json::from_str::<Input>(r#"{"runn": 1}"#).unwrap_err();
    assert!(bad.to_string().contains("unknown field `runn`"), "{bad}");
    let state: serde_json::Value = serde_json::from_str(ricochet_coin_rush::STATE_SCHEMA).unwrap();
    assert_eq!(state["type"], "object");
}
