//! `ricochet serve` answers scene queries (issue 22): the `/query` service (rays, points,
//! boxes, shapes) and Lichtblick's clicked point, answered on `/events`. The expected hits
//! come from `scenarios/platformer.toml` itself: its static tiles and coins never move, so
//! every answer is exact arithmetic on the file's positions and sizes. Bodies are numbered
//! in file order: floor_a 0, floor_b 1, floor_c 2, wall_left 3, wall_right 4, post 5,
//! ledge 6, high_ledge 7, platform 8, player 9, enemy_pit 10, enemy_patrol 11, coin_1 to
//! coin_5 12 to 16, all of generation 0.

use std::time::Duration;

use futures_util::SinkExt;
use prost::Message as _;
use ricochet_log::messages::fox::Log;
use serde_json::{Value, json};
use tokio_tungstenite::tungstenite::Message;

use crate::serve_client::*;

/// `(body, name, layer)` of each hit.
fn bodies(answer: &Value) -> Vec<(String, String, String)> {
    answer["hits"]
        .as_array()
        .unwrap()
        .iter()
        .map(|h| {
            let s = |k: &str| h[k].as_str().unwrap().to_owned();
            (s("body"), s("name"), s("layer"))
        })
        .collect()
}

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

fn pair(v: &Value) -> [f64; 2] {
    [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()]
}

async fn query(
    ws: &mut Ws,
    services: &Value,
    call_id: u32,
    request: Value,
) -> Result<Value, String> {
    call(ws, services, "/query", call_id, &request.to_string()).await
}

/// Rays, points, boxes and shapes on the platformer's static bodies, every answer from the
/// file's numbers.
#[test]
fn query_answers_rays_and_overlaps_exactly_on_the_platformers_static_bodies() {
    let mut server = serve(&["scenarios/platformer.toml", "--paused"]);
    runtime().block_on(async {
        let (mut ws, services) = open(&server, "foxglove.websocket.v1").await;
        let query_service = services["services"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["name"] == "/query")
            .expect("/query is advertised");
        assert_eq!(query_service["request"]["encoding"], "json");
        assert!(
            query_service["request"]["schema"]
                .as_str()
                .unwrap()
                .contains("max_distance")
        );

        // Straight down from (5.5, 10): coin_2 (centre y 3.8, radius 0.35: top 4.15), the
        // ledge (top y 3), floor_b (top y 0).
        let down = json!({"kind": "ray", "origin": [5.5, 10], "direction": [0, -3],
                          "max_distance": 20, "all": true});
        let all = query(&mut ws, &services, 1, down.clone()).await.unwrap();
        assert_eq!(all["frame"], 1, "paused after frame 0");
        assert_eq!(all["count"], 3);
        assert_eq!(all["truncated"], false);
        let names: Vec<String> = bodies(&all).into_iter().map(|b| b.1).collect();
        assert_eq!(names, ["coin_2", "ledge", "floor_b"]);
        let hits = all["hits"].as_array().unwrap();
        for (hit, (distance, y)) in hits.iter().zip([(5.85, 4.15), (7.0, 3.0), (10.0, 0.0)]) {
            assert!(near(hit["distance"].as_f64().unwrap(), distance), "{hit}");
            let p = pair(&hit["point"]);
            assert!(near(p[0], 5.5) && near(p[1], y), "{hit}");
            let n = pair(&hit["normal"]);
            assert!(near(n[0], 0.0) && near(n[1], 1.0), "{hit}");
        }
        // The first hit only, and the tiles only.
        let mut first = down.clone();
        first["all"] = json!(false);
        first["layers"] = json!(["tile"]);
        let ledge = query(&mut ws, &services, 2, first).await.unwrap();
        assert_eq!(
            bodies(&ledge),
            [("6:0".into(), "ledge".into(), "tile".into())]
        );
        assert_eq!(ledge["hits"][0]["distance"].as_f64(), Some(7.0));
        // Short of the coin: nothing.
        let mut short = down.clone();
        short["max_distance"] = json!(5.8);
        let none = query(&mut ws, &services, 3, short).await.unwrap();
        assert_eq!(none["count"], 0);
        assert_eq!(none["hits"], json!([]));

        // Inside high_ledge (x 20..26, y 5.5..6.5).
        let p = query(
            &mut ws,
            &services,
            4,
            json!({"kind": "point", "point": [23, 6]}),
        )
        .await
        .unwrap();
        assert_eq!(
            bodies(&p),
            [("7:0".into(), "high_ledge".into(), "tile".into())]
        );
        // On its top face: touching is not inside.
        let edge = query(
            &mut ws,
            &services,
            5,
            json!({"kind": "point", "point": [21, 6.5]}),
        )
        .await
        .unwrap();
        assert_eq!(edge["count"], 0, "{edge}");

        // A box over the left corner: wall_left (x -17..-16) and floor_a (x -16..-3, y
        // -1..0), in id order.
        let corner = json!({"kind": "aabb", "min": [-17, -1], "max": [-15, 1]});
        let b = query(&mut ws, &services, 6, corner).await.unwrap();
        let ids: Vec<String> = bodies(&b).into_iter().map(|b| b.0).collect();
        assert_eq!(ids, ["0:0", "3:0"]);

        // A circle of radius 1 at coin_5 (30, 0.8): the coin, and floor_c below (its top at
        // 0, the circle's bottom at -0.2); enemy_patrol (x 27.45..28.45 after frame 0) is
        // outside. With layers: the coin only.
        let circle = json!({"kind": "shape", "shape": {"kind": "circle", "radius": 1},
                            "position": [30, 0.8]});
        let s = query(&mut ws, &services, 7, circle.clone()).await.unwrap();
        let ids: Vec<String> = bodies(&s).into_iter().map(|b| b.0).collect();
        assert_eq!(ids, ["2:0", "16:0"]);
        let mut coins = circle;
        coins["layers"] = json!(["coin"]);
        let s = query(&mut ws, &services, 8, coins).await.unwrap();
        assert_eq!(
            bodies(&s),
            [("16:0".into(), "coin_5".into(), "coin".into())]
        );
        // A box turned a quarter turn: 0.2 wide, 4 tall once turned, standing on the
        // ledge's middle (5.5, 3) and reaching coin_2 above it.
        let turned = json!({"kind": "shape", "shape": {"kind": "obb", "half_extents": [2, 0.1]},
                            "position": [5.5, 4.9], "angle": std::f64::consts::FRAC_PI_2});
        let s = query(&mut ws, &services, 9, turned).await.unwrap();
        let ids: Vec<String> = bodies(&s).into_iter().map(|b| b.0).collect();
        assert_eq!(ids, ["6:0", "13:0"]);
    });
    drop(server.child.kill());
}

/// Bad requests are named failures, the connection stays, and the next good one is
/// answered.
#[test]
fn bad_queries_are_named_failures_and_the_connection_stays() {
    let server = serve(&["scenarios/platformer.toml", "--paused"]);
    runtime().block_on(async {
        let (mut ws, services) = open(&server, "foxglove.websocket.v1").await;
        let many_layers: Vec<String> = (0..4000).map(|i| format!("layer{i}")).collect();
        let huge = json!({"kind": "point", "point": [0, 0], "layers": many_layers}).to_string();
        assert!(huge.len() > 40_000 && huge.len() < 64 * 1024);
        let parts: Vec<Value> = (0..2000)
            .map(|_| json!({"kind": "circle", "radius": 1}))
            .collect();
        let cases: [(&str, &str); 11] = [
            ("{not json", "bad request"),
            (r#"{"kind": "ray", "origin": [NaN, 0], "direction": [1, 0], "max_distance": 1}"#, "bad request"),
            (r#"{"kind": "point", "point": [1e999, 0]}"#, "bad request"),
            (r#"{"kind": "point", "point": [2e15, 0]}"#, "point"),
            (r#"{"kind": "point", "point": [0, 0], "layers": ["lava"]}"#, "no layer \"lava\""),
            (r#"{"kind": "ray", "origin": [0, 0], "direction": [0, 0], "max_distance": 1}"#, "direction"),
            (r#"{"kind": "ray", "origin": [0, 0], "direction": [1, 0], "max_distance": -1}"#, "max_distance"),
            (r#"{"kind": "aabb", "min": [1, 0], "max": [0, 1]}"#, "min"),
            (r#"{"kind": "shape", "shape": {"kind": "circle", "radius": -1}, "position": [0, 0]}"#, "shape"),
            (r#"{"kind": "cone"}"#, "bad request"),
            (&huge, "no layer \"layer0\""),
        ];
        for (i, (request, says)) in cases.iter().enumerate() {
            let e = call(&mut ws, &services, "/query", 10 + i as u32, request)
                .await
                .unwrap_err();
            assert!(e.contains(says), "{request:.80}: {e}");
        }
        let compound = json!({"kind": "shape", "shape": {"kind": "compound", "parts": parts},
                              "position": [0, 0]});
        let e = query(&mut ws, &services, 30, compound).await.unwrap_err();
        assert!(e.starts_with("shape"), "{e}");
        // A huge circle sees every body (17), still one answer.
        let everything = json!({"kind": "shape", "shape": {"kind": "circle", "radius": 1e6},
                                "position": [0, 0]});
        let all = query(&mut ws, &services, 31, everything).await.unwrap();
        assert_eq!(all["count"], 17);
        assert_eq!(all["hits"].as_array().unwrap().len(), 17);
    });
}

/// Advertises `/clicked_point` as Lichtblick's 3D panel does (its publish tool, JSON) on
/// the client's channel 7.
async fn advertise_click(ws: &mut Ws) {
    let advertise = json!({"op": "advertise", "channels": [{"id": 7, "topic": "/clicked_point",
        "encoding": "json", "schemaName": "geometry_msgs/PointStamped"}]});
    ws.send(Message::text(advertise.to_string())).await.unwrap();
}

/// Publishes a click at `(x, y)` in `frame`, as Lichtblick's `makePointMessage` writes it.
async fn click(ws: &mut Ws, frame: &str, x: f64, y: f64) {
    let message = json!({"header": {"stamp": {"sec": 1_764_745_200, "nsec": 0}, "frame_id": frame},
                         "point": {"x": x, "y": y, "z": 0}});
    let mut data = vec![1u8];
    data.extend_from_slice(&7u32.to_le_bytes());
    data.extend_from_slice(message.to_string().as_bytes());
    ws.send(Message::binary(data)).await.unwrap();
}

/// The next `click` line of `/events` (subscription 1; the frames' own lines are skipped).
async fn next_event(ws: &mut Ws) -> Log {
    loop {
        let (sub, _, payload) = next_data(ws).await;
        let line = Log::decode(payload.as_slice()).unwrap();
        if sub == 1 && line.name == "click" {
            return line;
        }
    }
}

/// A click is answered on `/events` with each body at the point and its state, in the
/// `world` frame and in the `view` frame the layout follows (the world's bounds' centre,
/// (10, 5), as the platformer has no focus body); a click in another frame is refused
/// with a status. Queries and clicks leave the recording as a replay makes it, byte for
/// byte, and no click line is in it.
#[test]
fn a_click_is_answered_on_events_and_the_recording_still_replays_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("session.mcap");
    let mut server = serve(&[
        "scenarios/platformer.toml",
        "--paused",
        "--record",
        out.to_str().unwrap(),
    ]);
    runtime().block_on(async {
        let (mut ws, _) = connect(&server.url, "foxglove.websocket.v1").await.unwrap();
        let info = next_json(&mut ws).await;
        assert_eq!(info["metadata"]["ROS_DISTRO"], "humble");
        let channels = next_json(&mut ws).await;
        subscribe_to(&mut ws, &channels, "/events", 1).await;
        advertise_click(&mut ws).await;
        tokio::time::sleep(Duration::from_millis(100)).await;
        // Inside coin_2 (centre (5.5, 3.8), radius 0.35).
        click(&mut ws, "world", 5.5, 3.75).await;
        let line = next_event(&mut ws).await;
        assert_eq!(line.name, "click");
        assert!(
            line.message.starts_with(
                "click at [5.5, 3.75]: coin_2 #13:0 (layer coin, static, \
                 shape {\"kind\":\"circle\",\"radius\":0.35}, position [5.5, 3.8], angle 0, \
                 velocity [0, 0], angular velocity 0,"
            ),
            "{}",
            line.message
        );
        assert!(!line.message.contains(';'), "one body: {}", line.message);
        // The same point from the view frame, whose origin is (10, 5).
        click(&mut ws, "view", -4.5, -1.25).await;
        let line = next_event(&mut ws).await;
        assert!(
            line.message
                .starts_with("click at [5.5, 3.75]: coin_2 #13:0 ("),
            "{}",
            line.message
        );
        // The player: dynamic, so its mass (1) is given; a runner, moving right from the
        // script's frame 0.
        click(&mut ws, "world", -12.0, 0.8).await;
        let line = next_event(&mut ws).await;
        assert!(
            line.message
                .starts_with("click at [-12, 0.8]: player #9:0 (layer player, dynamic,"),
            "{}",
            line.message
        );
        assert!(line.message.contains(", mass 1, "), "{}", line.message);
        assert!(
            line.message.contains(", runner: move 1, "),
            "{}",
            line.message
        );
        click(&mut ws, "world", 0.0, 10.0).await;
        assert_eq!(
            next_event(&mut ws).await.message,
            "click at [0, 10]: no body there"
        );
        click(&mut ws, "map", 0.0, 0.0).await;
        let (level, text) = next_status(&mut ws).await;
        assert_eq!(level, 2);
        assert!(text.contains("frame \"map\""), "{text}");
        // A few frames on, with a query between them.
        let (mut calls, services) = open(&server, "foxglove.websocket.v1").await;
        call(&mut calls, &services, "/step", 1, r#"{"frames": 5}"#)
            .await
            .unwrap();
        let ray =
            json!({"kind": "ray", "origin": [5.5, 10], "direction": [0, -1], "max_distance": 20});
        let hit = query(&mut calls, &services, 2, ray).await.unwrap();
        assert_eq!(hit["frame"], 6);
        click(&mut ws, "world", 23.0, 7.3).await;
        let line = next_event(&mut ws).await;
        assert!(line.message.contains("coin_4 #15:0"), "{}", line.message);
        call(&mut calls, &services, "/step", 3, r#"{"frames": 2}"#)
            .await
            .unwrap();
    });
    assert!(terminate(&mut server, Duration::from_secs(10)).success());
    let log = ricochet_log::read_log_file(&out).unwrap();
    assert!(
        !log.iter()
            .any(|m| m.topic == "/events" && m.data["name"] == "click"),
        "clicks are answered live, never recorded"
    );
    assert_eq!(replays_byte_for_byte(&out), 8, "frames 0 to 7");
}

/// After an overflow the simulation holds the frame that overflowed, which no client was
/// sent (nor the recording holds): a query or a click is refused, saying so, until a seek
/// back; then it is answered again.
#[test]
fn after_an_overflow_queries_and_clicks_are_refused_until_a_seek_back() {
    let dir = tempfile::tempdir().unwrap();
    // Gravity of 1e154: the rock's kinetic energy passes f64 within about 80 frames.
    let scenario = dir.path().join("overflow.toml");
    std::fs::write(
        &scenario,
        "layers = [\"a\"]\nframes = 1000\nworld.gravity = [0, -1e154]\n[[bodies]]\nname = \
         \"rock\"\nlayer = \"a\"\nshape = { kind = \"circle\", radius = 1 }\n",
    )
    .unwrap();
    let server = serve(&[scenario.to_str().unwrap(), "--paused"]);
    runtime().block_on(async {
        let (mut ws, services) = open(&server, "foxglove.websocket.v1").await;
        let failed = call(&mut ws, &services, "/step", 1, r#"{"frames": 500}"#)
            .await
            .unwrap_err();
        assert!(failed.contains("overflowed"), "{failed}");
        let point = json!({"kind": "point", "point": [0, 0]});
        let refused = query(&mut ws, &services, 2, point.clone())
            .await
            .unwrap_err();
        assert!(refused.contains("overflowed"), "{refused}");
        advertise_click(&mut ws).await;
        click(&mut ws, "world", 0.0, 0.0).await;
        let (level, text) = next_status(&mut ws).await;
        assert_eq!(level, 1);
        assert!(
            text.starts_with("clicked point not answered: ") && text.contains("overflowed"),
            "{text}"
        );
        // Back after frame 0, which moves nothing (the initial state, `pipeline.rs`): the
        // rock is still at the origin.
        let back = call(&mut ws, &services, "/seek", 3, r#"{"frame": 1}"#).await;
        assert_eq!(back.unwrap()["frame"], 1);
        let rock = query(&mut ws, &services, 4, point).await.unwrap();
        assert_eq!(bodies(&rock), [("0:0".into(), "rock".into(), "a".into())]);
    });
}

/// An answer lists at most 256 hits, the first by the API's order, and counts them all:
/// 300 unit circles on the x axis, 3 apart (body `i` at `x = 3 i`), all in one box and on
/// one ray.
#[test]
fn an_answer_lists_at_most_256_hits_and_counts_them_all() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("row.toml");
    let mut text = String::from("layers = [\"a\"]\n");
    for i in 0..300 {
        text += &format!(
            "[[bodies]]\nname = \"c{i}\"\nlayer = \"a\"\nkind = \"static\"\nshape = {{ kind = \
             \"circle\", radius = 1 }}\nposition = [{}, 0]\n",
            3 * i
        );
    }
    std::fs::write(&scenario, text).unwrap();
    let server = serve(&[scenario.to_str().unwrap(), "--paused"]);
    runtime().block_on(async {
        let (mut ws, services) = open(&server, "foxglove.websocket.v1").await;
        let boxed = json!({"kind": "aabb", "min": [-2, -2], "max": [900, 2]});
        let all = query(&mut ws, &services, 1, boxed).await.unwrap();
        assert_eq!(all["count"], 300);
        assert_eq!(all["truncated"], true);
        let ids: Vec<String> = bodies(&all).into_iter().map(|b| b.0).collect();
        let first: Vec<String> = (0..256).map(|i| format!("{i}:0")).collect();
        assert_eq!(ids, first);
        // From the left, along the row: circle i is met at distance 3 i - 1 + 5.
        let ray = json!({"kind": "ray", "origin": [-5, 0], "direction": [1, 0],
                         "max_distance": 1000, "all": true});
        let hits = query(&mut ws, &services, 2, ray).await.unwrap();
        assert_eq!(hits["count"], 300);
        assert_eq!(hits["truncated"], true);
        let listed = hits["hits"].as_array().unwrap();
        assert_eq!(listed.len(), 256);
        for (i, h) in listed.iter().enumerate() {
            assert_eq!(h["body"], format!("{i}:0"));
            assert!(
                near(h["distance"].as_f64().unwrap(), 3.0 * i as f64 + 4.0),
                "{h}"
            );
        }
    });
}
