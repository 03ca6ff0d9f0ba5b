//! Rooms (`ricochet_serve::serve_rooms`, and `ricochet serve`'s `/rooms/NAME`): rooms step
//! independently, each recording only its own players' commands and replaying byte for
//! byte; a room whose game panics closes with its recording complete while another goes
//! on; bad room names and bad inputs are refused by name; the per-room and server-wide
//! caps; an empty room closes after its grace (those three in `serve_rooms/refusals.rs`).
//! Loopback only; every wait bounded.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use futures_util::StreamExt;
use ricochet_serve::RoomOptions;
use ricochet_sim::Player;
use ricochet_sim::prelude::*;
use serde_json::Value;
use tokio_tungstenite::tungstenite::Message;

use crate::serve_client::*;

mod game;
mod harness;
mod refusals;

use game::{PANIC_AT, Push, new_game};
use harness::{
    Rooms, commands, enter, next_game, quiet, replays_byte_for_byte, status_within, until_pushes,
    within,
};

#[test]
fn two_rooms_step_apart_each_recording_its_own_players_and_replaying_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let server = Rooms::start(RoomOptions {
        record: Some(dir.path().to_path_buf()),
        ..quiet()
    });
    runtime().block_on(async {
        let (mut ada, channels, services) = enter(&server.url("alpha")).await;
        let topics: Vec<&str> = channels["channels"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["topic"].as_str().unwrap())
            .collect();
        // What a client publishes on `/input` is the game's input: the server's record of
        // the commands is advertised apart, and the game's state is there.
        assert!(topics.contains(&"/input/recorded"), "{topics:?}");
        assert!(!topics.contains(&"/input"), "{topics:?}");
        assert!(topics.contains(&"/game") && topics.contains(&"/scene"));
        let joined = call(&mut ada, &services, "/join", 1, r#"{"name": "ada"}"#)
            .await
            .unwrap();
        assert_eq!(joined["player"], 1);
        assert_eq!(joined["input_schema"]["required"][0], "push");
        subscribe_to(&mut ada, &channels, "/game", 1).await;
        advertise_input(&mut ada).await;
        publish(&mut ada, r#"{"push": [1, 0]}"#).await;
        let alpha_at = until_pushes(&mut ada, 1).await["frame"].as_u64().unwrap();

        // Beta starts at frame 0 while alpha is well past it.
        let (mut bob, channels_b, services_b) = enter(&server.url("beta")).await;
        subscribe_to(&mut bob, &channels_b, "/game", 1).await;
        let beta_first = next_game(&mut bob, 1).await["frame"].as_u64().unwrap();
        let alpha_now = next_game(&mut ada, 1).await["frame"].as_u64().unwrap();
        assert!(alpha_now >= alpha_at);
        assert!(
            beta_first < alpha_now,
            "beta at {beta_first}, alpha at {alpha_now}"
        );
        let joined = call(&mut bob, &services_b, "/join", 1, r#"{"name": "bob"}"#)
            .await
            .unwrap();
        // Players are numbered per room.
        assert_eq!(joined["player"], 1);
        advertise_input(&mut bob).await;
        publish(&mut bob, r#"{"push": [0, 2]}"#).await;
        publish(&mut bob, r#"{"push": [0, 3]}"#).await;
        until_pushes(&mut bob, 2).await;

        let listed = call(&mut bob, &services_b, "/rooms", 2, "{}")
            .await
            .unwrap();
        let rooms = listed["rooms"].as_array().unwrap();
        let names: Vec<&str> = rooms.iter().map(|r| r["name"].as_str().unwrap()).collect();
        assert_eq!(names, ["alpha", "beta"]);
        assert!(rooms.iter().all(|r| r["players"] == 1 && r["clients"] == 1));

        // Disconnecting is leaving: bob's ball goes, at beta's next frame.
        drop(bob);
        let deadline = Instant::now() + Duration::from_secs(10);
        // Once beta shows no player, the leave is applied; two frames later it is recorded.
        let mut gone_at = None;
        for n in 10.. {
            let listed = call(&mut ada, &services, "/rooms", n, "{}").await.unwrap();
            let beta = &listed["rooms"][1];
            let frame = beta["frame"].as_u64().unwrap();
            if beta["players"] == 0 {
                let at = *gone_at.get_or_insert(frame);
                if frame >= at + 2 {
                    break;
                }
            }
            assert!(
                Instant::now() < deadline,
                "bob's leave not recorded: {listed}"
            );
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        let left = call(&mut ada, &services, "/leave", 2, "{}").await.unwrap();
        assert_eq!(left["left"], 1);
        let game = within(async {
            loop {
                let g = next_game(&mut ada, 1).await;
                if g["players"] == 0 {
                    return g;
                }
            }
        })
        .await;
        assert_eq!(game["pushes"], 1);
    });
    let served = server.stop();
    assert_eq!((served.opened, served.failed), (2, 0));

    let alpha = dir.path().join("alpha.mcap");
    let beta = dir.path().join("beta.mcap");
    let a = commands(&alpha);
    let b = commands(&beta);
    let kinds = |c: &[Value]| -> Vec<String> {
        c.iter()
            .map(|m| {
                if let Some(name) = m["join"].as_str() {
                    format!("join {name}")
                } else if m["leave"] == true {
                    format!("leave {}", m["player"])
                } else {
                    format!("input {}", m["input"].as_str().unwrap())
                }
            })
            .collect()
    };
    assert_eq!(
        kinds(&a),
        ["join ada", r#"input {"push": [1, 0]}"#, "leave 1"]
    );
    assert_eq!(
        kinds(&b),
        [
            "join bob",
            r#"input {"push": [0, 2]}"#,
            r#"input {"push": [0, 3]}"#,
            "leave 1"
        ]
    );
    for (log, room) in [(&alpha, "alpha"), (&beta, "beta")] {
        let (same, frames) = replays_byte_for_byte(log, room, dir.path());
        assert!(frames > 0);
        assert!(same, "{room}'s recording replays byte for byte");
    }
}

#[test]
fn a_room_whose_game_panics_closes_with_its_recording_whole_and_another_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let server = Rooms::start(RoomOptions {
        record: Some(dir.path().to_path_buf()),
        ..quiet()
    });
    runtime().block_on(async {
        let (mut calm, channels, _) = enter(&server.url("calm")).await;
        subscribe_to(&mut calm, &channels, "/game", 1).await;
        let (mut boom, _, _) = enter(&server.url("boom")).await;
        // The room's clients are told why, then closed.
        let (level, why) = status_within(&mut boom).await;
        assert_eq!(level, 2);
        assert!(why.contains("panicked"), "{why}");
        assert!(
            why.contains(&format!("the test game panics at frame {PANIC_AT}")),
            "{why}"
        );
        assert!(
            why.contains(&format!("frames 0 to {}", PANIC_AT - 1)),
            "{why}"
        );
        let closed = loop {
            match tokio::time::timeout(Duration::from_secs(10), boom.next())
                .await
                .expect("closed within 10 s")
            {
                Some(Ok(Message::Close(frame))) => break frame,
                Some(Ok(_)) => {}
                other => panic!("{other:?}"),
            }
        };
        assert_eq!(u16::from(closed.unwrap().code), 1001);
        // The other room goes on stepping.
        let before = next_game(&mut calm, 1).await["frame"].as_u64().unwrap();
        let mut after = before;
        while after < before + 20 {
            after = next_game(&mut calm, 1).await["frame"].as_u64().unwrap();
        }
    });
    let served = server.stop();
    assert_eq!((served.opened, served.failed), (2, 1));
    let log = dir.path().join("boom.mcap");
    let (same, frames) = replays_byte_for_byte(&log, "boom", dir.path());
    assert_eq!(frames, PANIC_AT, "frames 0 to {}", PANIC_AT - 1);
    assert!(same);
}

/// Eight rooms of four players each, pushing ten times a second for 2 s: every room
/// steps, and every push lands in its own room's state.
#[test]
fn eight_rooms_of_four_players_keep_stepping_under_inputs() {
    const ROOMS: usize = 8;
    const PLAYERS: usize = 4;
    const PUSHES: u64 = 20;
    let server = Rooms::start(quiet());
    let urls: Vec<String> = (0..ROOMS)
        .map(|r| server.url(&format!("load-{r}")))
        .collect();
    runtime().block_on(async {
        let mut clients = Vec::new();
        for url in &urls {
            for p in 0..PLAYERS {
                let (mut ws, channels, services) = enter(url).await;
                let name = format!("p{p}");
                call(
                    &mut ws,
                    &services,
                    "/join",
                    1,
                    &format!(r#"{{"name": "{name}"}}"#),
                )
                .await
                .unwrap();
                if p == 0 {
                    subscribe_to(&mut ws, &channels, "/game", 1).await;
                }
                advertise_input(&mut ws).await;
                clients.push(ws);
            }
        }
        let mut tick = tokio::time::interval(Duration::from_millis(100));
        for k in 0..PUSHES {
            tick.tick().await;
            for ws in &mut clients {
                publish(ws, &format!(r#"{{"push": [{k}, 0]}}"#)).await;
            }
        }
        for r in 0..ROOMS {
            let game = until_pushes(&mut clients[r * PLAYERS], PUSHES * PLAYERS as u64).await;
            assert_eq!(game["players"], PLAYERS as u64);
        }
    });
    let served = server.stop();
    assert_eq!((served.opened, served.failed), (ROOMS as u64, 0));
    eprintln!(
        "{ROOMS} rooms x {PLAYERS} players: {} frames; late p50 {:.3} ms, p99 {:.3} ms, max {:.3} ms",
        served.frames, served.late_ms[0], served.late_ms[1], served.late_ms[2]
    );
}

/// `ricochet serve SCENARIO` keeps its plain URL and hosts rooms of the scenario's game:
/// no players, inputs as the plain server takes them, one recording per room that
/// `ricochet replay` replays.
#[test]
fn ricochet_serve_hosts_rooms_of_its_scenario_beside_the_plain_url() {
    let dir = tempfile::tempdir().unwrap();
    let rooms_dir: PathBuf = dir.path().join("rooms");
    std::fs::create_dir(&rooms_dir).unwrap();
    let mut server = serve(&["--record-rooms", rooms_dir.to_str().unwrap()]);
    runtime().block_on(async {
        let (mut ws, channels, services) = enter(&format!("{}/rooms/lobby", server.url)).await;
        let bad = call(&mut ws, &services, "/join", 1, r#"{"name": "ada"}"#).await;
        assert!(bad.unwrap_err().contains("this game has no players"));
        subscribe_to(&mut ws, &channels, "/input/recorded", 1).await;
        advertise_input(&mut ws).await;
        publish(
            &mut ws,
            r#"{"action": "turn", "body": "ship", "input": 0.5}"#,
        )
        .await;
        let (_, _, payload) = next_data(&mut ws).await;
        assert!(!payload.is_empty());
        // The plain URL is today's server, and lists the rooms too.
        let (mut plain, _, plain_services) = enter(&server.url).await;
        let listed = call(&mut plain, &plain_services, "/rooms", 1, "{}")
            .await
            .unwrap();
        assert_eq!(listed["rooms"][0]["name"], "lobby");
        assert_eq!(listed["rooms"][0]["clients"], 1);
    });
    let status = terminate(&mut server, Duration::from_secs(10));
    assert!(status.success());
    let log = rooms_dir.join("lobby.mcap");
    let out = dir.path().join("again.mcap");
    let replay = std::process::Command::new(env!("CARGO_BIN_EXE_ricochet"))
        .args(["replay", log.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        replay.status.success(),
        "{}",
        String::from_utf8_lossy(&replay.stderr)
    );
}

/// One game value through every loop: served in a room (a client joins, pushes twice and
/// leaves), then the room's recorded commands given to the game's own plain loop, to a
/// golden check and to a replay. The replay is the recording byte for byte; the golden,
/// written by a session of its own from the same commands, holds the same messages; the
/// plain loop ends in the same world (equal checksums).
#[test]
fn one_game_served_then_plain_golden_and_replayed_agree() {
    use ricochet_record::golden::{self, Command};
    let dir = tempfile::tempdir().unwrap();
    let server = Rooms::start(RoomOptions {
        record: Some(dir.path().to_path_buf()),
        ..quiet()
    });
    runtime().block_on(async {
        let (mut ada, channels, services) = enter(&server.url("every")).await;
        call(&mut ada, &services, "/join", 1, r#"{"name": "ada"}"#)
            .await
            .unwrap();
        subscribe_to(&mut ada, &channels, "/game", 1).await;
        advertise_input(&mut ada).await;
        // As serde writes them, so that the golden's typed inputs are the same text.
        publish(&mut ada, r#"{"push":[1.0,0.0]}"#).await;
        until_pushes(&mut ada, 1).await;
        publish(&mut ada, r#"{"push":[0.0,-2.5]}"#).await;
        until_pushes(&mut ada, 2).await;
        call(&mut ada, &services, "/leave", 2, "{}").await.unwrap();
        within(async { while next_game(&mut ada, 1).await["players"] != 0 {} }).await;
    });
    server.stop();
    let served = dir.path().join("every.mcap");
    let log = ricochet_log::LogFile::open(&served).unwrap();

    // Replayed: byte for byte.
    let again = dir.path().join("again.mcap");
    let (sim, game) = new_game("every");
    let replayed = ricochet_record::replay::replay(
        &log,
        sim,
        game,
        ricochet_record::log_writer(&again).unwrap(),
    )
    .unwrap();
    replayed.sink.finish().unwrap();
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(&served).unwrap()
    );

    // The recorded commands, as a script.
    let script: Vec<(u64, Command<Push>)> = ricochet_record::replay::commands(&log)
        .unwrap()
        .into_iter()
        .map(|c| {
            let command = match (&c.join, c.leave, &c.input) {
                (Some(name), _, _) => Command::Join(name.clone()),
                (None, true, _) => Command::Leave(Player(c.player)),
                (None, false, Some(text)) => {
                    Command::Input(Player(c.player), serde_json::from_str(text).unwrap())
                }
                other => panic!("{other:?}"),
            };
            (c.frame, command)
        })
        .collect();
    assert_eq!(script.len(), 4, "join, two pushes, leave");
    let last = replayed.frames - 1;

    // Plain: the game's own loop, the same commands at the same frames.
    let (sim, game) = new_game("every");
    let mut plain = GameLoop::new(sim, game);
    for frame in 0..=last {
        for (_, c) in script.iter().filter(|(f, _)| *f == frame) {
            match c {
                Command::Join(n) => drop(plain.join(n)),
                Command::Leave(p) => drop(plain.leave(*p)),
                Command::Input(p, i) => {
                    let i: Push = serde_json::from_value(serde_json::to_value(i).unwrap()).unwrap();
                    drop(plain.input(*p, i));
                }
            }
        }
        plain.step().unwrap();
    }
    assert_eq!(plain.sim().checksum(), replayed.sim.checksum());
    assert_eq!(plain.game().state.pushes, 2);

    // Every chunk of the game's logs has a message index: Lichtblick refuses a log with a
    // chunk of channels alone (an attachment written after the channels made one).
    for log in [&served, &again] {
        let bytes = std::fs::read(log).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        assert!(!summary.chunk_indexes.is_empty());
        for chunk in &summary.chunk_indexes {
            assert!(
                !chunk.message_index_offsets.is_empty(),
                "{}: a chunk without messages at {}",
                log.display(),
                chunk.chunk_start_offset
            );
        }
    }

    // Golden: a session of its own, from the script, holds the served room's messages.
    let golden_path = dir.path().join("golden.mcap");
    let (sim, game) = new_game("every");
    golden::check_game_or_bless(&golden_path, sim, game, last, &script, true).unwrap();
    let (a, b) = (
        ricochet_log::diff::open(&golden_path).unwrap(),
        ricochet_log::diff::open(&served).unwrap(),
    );
    let report = ricochet_log::diff::diff_files(&a, &b, 0.0, None).unwrap();
    assert!(report.first.is_none(), "{:?}", report.first);
}
