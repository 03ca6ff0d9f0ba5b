//! A scripted two-player match of Coin Rush, golden-checked (`tests/golden/match.mcap`),
//! replayed through the library byte for byte, and read back: the recording's `/game`
//! agrees with the game's final state and with what the arena's geometry says happens.
//!
//! The match (frames are the frames the commands land in):
//! - 1: ada joins (player 1, at spawn 0, x = -4) and bob (player 2, at spawn 1, x = 4);
//! - 10: bob zaps left along y = 1, seen frame 9: nothing between x = 4 and ada's right
//!   face at -3.6 (7.6 < the range of 12), so ada is stunned for frames 10 to 69;
//! - 12: ada asks to run right while stunned: she starts at frame 70, when the stun ends;
//! - 20: bob runs right at 6 units/s (0.1 a frame): after frame `f` he is at
//!   `4 + 0.1 (f - 19)`; his right face (+0.4) meets the floor coin at x = 8 (radius 0.35)
//!   past 7.65, so he scores in frame 52 and the coin is back in frame 352;
//! - 30 and 31: bob sends a run of 5 and a zap of a frame not yet stepped: both refused;
//! - 300: ada, against the right wall since frame ~260, runs left: over x = 8 after the
//!   coin came back (frame 363), then over the coin at x = -8 (frame 523): 2 points;
//! - 580: bob leaves.

use std::path::PathBuf;
use std::sync::Mutex;

use ricochet_coin_rush::{CoinRush, Input, STUN_FRAMES, State, Zap};
use ricochet_log::LogFile;
use ricochet_record::golden::{self, Command};
use ricochet_sim::prelude::*;

/// Frames after frame 0.
const FRAMES: u64 = 600;

const ADA: Player = Player(1);
const BOB: Player = Player(2);

fn golden_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/match.mcap")
}

fn run(x: f64) -> Input {
    Input {
        run: Some(x),
        ..Input::default()
    }
}

fn zap(dir: [f64; 2], seen: u64) -> Input {
    Input {
        zap: Some(Zap { dir, seen }),
        ..Input::default()
    }
}

fn script() -> Vec<(u64, Command<Input>)> {
    vec![
        (1, Command::Join("ada".into())),
        (1, Command::Join("bob".into())),
        (10, Command::Input(BOB, zap([-1.0, 0.0], 9))),
        (12, Command::Input(ADA, run(1.0))),
        (20, Command::Input(BOB, run(1.0))),
        (30, Command::Input(BOB, run(5.0))),
        (31, Command::Input(BOB, zap([-1.0, 0.0], 40))),
        (
            450,
            Command::Input(
                BOB,
                Input {
                    jump: true,
                    ..Input::default()
                },
            ),
        ),
        (300, Command::Input(ADA, run(-1.0))),
        (580, Command::Leave(BOB)),
    ]
}

/// The match, checked against its golden: the game at the end. One check at a time: each
/// writes `match.new.mcap` beside the golden.
fn checked() -> CoinRush {
    static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());
    let _held = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (sim, game) = CoinRush::new().unwrap();
    golden::check_game(golden_path(), sim, game, FRAMES, &script()).unwrap()
}

/// Every `/game` message of a log, in frame order.
fn states(log: &LogFile) -> Vec<State> {
    log.topic_messages("/game")
        .unwrap()
        .map(|m| serde_json::from_value(m.unwrap().data).unwrap())
        .collect()
}

fn score(s: &State, name: &str) -> Option<u32> {
    s.players.iter().find(|p| p.name == name).map(|p| p.score)
}

fn stunned(s: &State, name: &str) -> Option<bool> {
    s.players.iter().find(|p| p.name == name).map(|p| p.stunned)
}

#[test]
fn the_match_is_its_golden_and_ends_as_the_geometry_says() {
    let game = checked();
    let end = game.state().unwrap();
    assert_eq!(end.frame, FRAMES);
    assert_eq!(end.players.len(), 1, "bob left: {:?}", end.players);
    assert_eq!(end.players[0].name, "ada");
    assert_eq!(end.players[0].score, 2);
}

#[test]
fn the_recorded_game_channel_agrees_with_the_game_and_the_geometry() {
    let game = checked();
    let log = LogFile::open(&golden_path()).unwrap();
    let all = states(&log);
    assert_eq!(
        all.len() as u64,
        FRAMES + 1,
        "a state per frame, 0 to {FRAMES}"
    );
    for (f, s) in all.iter().enumerate() {
        assert_eq!(s.frame, f as u64);
    }
    // The last state recorded is the game's own at the end.
    assert_eq!(all.last(), game.state());
    // Ada stunned from the frame the zap lands in, for STUN_FRAMES frames.
    for s in &all[1..] {
        let want = (10..10 + STUN_FRAMES).contains(&s.frame);
        assert_eq!(stunned(s, "ada"), Some(want), "frame {}", s.frame);
    }
    // Bob's point in frame 52, the coin (slot 4) away from then to frame 351.
    assert_eq!(score(&all[51], "bob"), Some(0));
    assert_eq!(score(&all[52], "bob"), Some(1));
    // Ada, stopped by the right wall at x = 16 - 0.5 - 0.4 = 15.1, runs left from frame
    // 300: after frame `f` she is at `15.1 - 0.1 (f - 299)`; her left face (-0.4) meets the
    // coin at x = 8 (back since 352) below 8.35, in frame 363, and the one at x = -8 below
    // -7.65, in frame 523.
    for s in &all {
        let f = s.frame;
        assert_eq!(s.coins[4], !(52..352).contains(&f) && f < 363, "frame {f}");
        assert_eq!(s.coins[3], f < 523, "frame {f}");
        assert_eq!(s.coins[..3], [true; 3], "frame {f}");
    }
    assert_eq!(score(&all[579], "bob"), Some(1));
    assert_eq!(score(&all[580], "bob"), None);
    assert_eq!(score(&all[362], "ada"), Some(0));
    assert_eq!(score(&all[363], "ada"), Some(1));
    assert_eq!(score(&all[522], "ada"), Some(1));
    assert_eq!(score(&all[523], "ada"), Some(2));
    // The two refused inputs are in the log's events, named by field.
    let refusals: Vec<String> = log
        .topic_messages("/events")
        .unwrap()
        .map(|m| m.unwrap().data["message"].as_str().unwrap_or("").to_owned())
        .filter(|m| m.contains("refused"))
        .collect();
    assert_eq!(refusals.len(), 2, "{refusals:?}");
    assert!(refusals[0].contains("run: from -1 to 1"), "{}", refusals[0]);
    assert!(
        refusals[1].contains("zap.seen: frame 40"),
        "{}",
        refusals[1]
    );
}

#[test]
fn the_golden_replays_byte_for_byte_with_a_fresh_game() {
    checked();
    let recorded = LogFile::open(&golden_path()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let again = dir.path().join("again.mcap");
    let (sim, game) = CoinRush::new().unwrap();
    let out = ricochet_record::log_writer(&again).unwrap();
    let replayed = ricochet_record::replay::replay(&recorded, sim, game, out).unwrap();
    replayed.sink.finish().unwrap();
    assert_eq!(replayed.frames, FRAMES + 1);
    assert_eq!(replayed.commands, script().len());
    let (a, b) = (
        std::fs::read(golden_path()).unwrap(),
        std::fs::read(&again).unwrap(),
    );
    assert!(a == b, "the replay's log differs from the golden");
}
