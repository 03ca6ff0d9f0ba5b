//! Rooms refusing by name: bad room names, bad calls and a bad input; the per-room and
//! server-wide caps turning clients away; an empty room closing after its grace. Loopback
//! only; every wait bounded.

use super::*;

/// The HTTP status and body of a refused handshake.
async fn refused_http(url: &str) -> (u16, String) {
    use tokio_tungstenite::tungstenite::Error;
    use tokio_tungstenite::tungstenite::client::IntoClientRequest;
    let mut request = url.into_client_request().unwrap();
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        "foxglove.websocket.v1".parse().unwrap(),
    );
    match tokio_tungstenite::connect_async(request).await {
        Err(Error::Http(response)) => (
            response.status().as_u16(),
            String::from_utf8_lossy(response.body().as_deref().unwrap_or(b"")).into_owned(),
        ),
        Err(e) => panic!("{url}: {e}"),
        Ok(_) => panic!("{url} was accepted"),
    }
}

#[test]
fn bad_room_names_bad_calls_and_a_bad_input_are_refused_by_name() {
    let server = Rooms::start(quiet());
    runtime().block_on(async {
        let long = "x".repeat(65);
        for path in [
            "/rooms/",
            "/rooms",
            "/rooms/a.b",
            "/rooms/a/b",
            &format!("/rooms/{long}"),
        ] {
            let (status, body) = refused_http(&format!("{}{path}", server.base)).await;
            assert_eq!(status, 400, "{path}");
            assert!(
                body.contains("1 to 64 of A-Z, a-z, 0-9, _ and -"),
                "{path}: {body}"
            );
        }
        let (status, body) = refused_http(&format!("{}/", server.base)).await;
        assert_eq!(status, 400);
        assert!(body.contains("connect to /rooms/NAME"), "{body}");
        // 64 characters is a name.
        let (_ws, _, _) = enter(&server.url(&"y".repeat(64))).await;

        let (mut ws, channels, services) = enter(&server.url("lobby")).await;
        let bad = call(&mut ws, &services, "/join", 1, r#"{"nam": "ada"}"#).await;
        assert!(bad.unwrap_err().contains("unknown field `nam`"));
        let bad = call(&mut ws, &services, "/join", 2, r#"{"name": ""}"#).await;
        assert!(bad.unwrap_err().contains("a name of 1 to 64 bytes"));
        let bad = call(&mut ws, &services, "/join", 3, r#"{"name": "nobody"}"#).await;
        assert_eq!(bad.unwrap_err(), "nobody may not play");
        let bad = call(&mut ws, &services, "/leave", 4, "{}").await;
        assert_eq!(bad.unwrap_err(), "this client has not joined");
        // Refused joins the session saw used numbers 1 and 2 (a bad request never reached
        // it): the numbers follow the order of joins, refused or not.
        let joined = call(&mut ws, &services, "/join", 5, r#"{"name": "ada"}"#)
            .await
            .unwrap();
        assert_eq!(joined["player"], 3);
        let again = call(&mut ws, &services, "/join", 6, r#"{"name": "ada"}"#).await;
        assert!(again.unwrap_err().contains("already joined, as player 3"));
        let bad = call(&mut ws, &services, "/rooms", 7, r#"{"create": "no way"}"#).await;
        assert!(bad.unwrap_err().contains("1 to 64 of A-Z"));
        // A timeline request (the SDK's PlaybackControlRequest: play, seek to 0) is told
        // it has no place in a room, and not kept.
        let mut timeline = vec![3u8, 0];
        timeline.extend_from_slice(&1.0f32.to_le_bytes());
        timeline.push(1);
        timeline.extend_from_slice(&0u64.to_le_bytes());
        timeline.extend_from_slice(&2u32.to_le_bytes());
        timeline.extend_from_slice(b"tl");
        futures_util::SinkExt::send(&mut ws, Message::binary(timeline))
            .await
            .unwrap();
        let (level, why) = status_within(&mut ws).await;
        assert_eq!(level, 1);
        assert_eq!(why, "a room has no timeline and answers no clicked points");

        subscribe_to(&mut ws, &channels, "/game", 1).await;
        advertise_input(&mut ws).await;
        publish(&mut ws, r#"{"push": [1, 2], "jump": true}"#).await;
        let (level, why) = status_within(&mut ws).await;
        assert_eq!(level, 2);
        assert!(
            why.starts_with("input refused: unknown field `jump`"),
            "{why}"
        );
        publish(&mut ws, r#"{"push": [1]}"#).await;
        let (_, why) = status_within(&mut ws).await;
        assert!(why.contains("input refused: invalid length 1"), "{why}");
        publish(&mut ws, r#"{"push": [1, 2]}"#).await;
        // The refused inputs changed nothing: one push in all.
        let game = until_pushes(&mut ws, 1).await;
        assert_eq!(game["players"], 1);
        let mut later = game;
        for _ in 0..5 {
            later = next_game(&mut ws, 1).await;
        }
        assert_eq!(later["pushes"], 1);
    });
    server.stop();
}

/// Connects and reads what comes until the server closes: the last status and the close
/// code, or `None` if it stays open (it gets its channels).
async fn turned_away(url: &str) -> Option<(String, u16)> {
    let (mut ws, _) = connect(url, "foxglove.websocket.v1").await.unwrap();
    let mut status = String::new();
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .expect("a message within 10 s");
        match m {
            Some(Ok(Message::Text(t))) => {
                let v: Value = serde_json::from_str(t.as_str()).unwrap();
                if v["op"] == "status" {
                    status = v["message"].as_str().unwrap().to_owned();
                }
                if v["op"] == "advertise" {
                    return None;
                }
            }
            Some(Ok(Message::Close(frame))) => {
                return Some((status, u16::from(frame.unwrap().code)));
            }
            Some(Ok(_)) => {}
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn the_room_and_server_caps_turn_clients_away_by_name_and_empty_rooms_close() {
    let dir = tempfile::tempdir().unwrap();
    let server = Rooms::start(RoomOptions {
        record: Some(dir.path().to_path_buf()),
        max_clients_per_room: 2,
        max_clients: 3,
        max_rooms: 2,
        grace: Duration::from_millis(300),
        ..quiet()
    });
    runtime().block_on(async {
        let (_a1, _, _) = enter(&server.url("a")).await;
        let (_a2, _, _) = enter(&server.url("a")).await;
        assert_eq!(
            turned_away(&server.url("a")).await,
            Some(("room a is full, at most 2 clients".to_owned(), 1013))
        );
        let (mut b, _, services) = enter(&server.url("b")).await;
        assert_eq!(
            turned_away(&server.url("c")).await,
            Some((
                "too many clients on this server, at most 3".to_owned(),
                1013
            ))
        );
        let bad = call(&mut b, &services, "/rooms", 1, r#"{"create": "c"}"#).await;
        assert_eq!(bad.unwrap_err(), "too many rooms, at most 2");
        drop(_a1);
        drop(_a2);
        // Room a, empty, closes after its grace: its recording is in place, and a new
        // client makes a new room a.
        let deadline = Instant::now() + Duration::from_secs(10);
        let mut n = 2;
        loop {
            let listed = call(&mut b, &services, "/rooms", n, "{}").await.unwrap();
            n += 1;
            let names: Vec<Value> = listed["rooms"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| r["name"].clone())
                .collect();
            if names == [Value::from("b")] {
                break;
            }
            assert!(Instant::now() < deadline, "room a still open: {listed}");
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        assert!(dir.path().join("a.mcap").is_file());
        let made = call(&mut b, &services, "/rooms", n, r#"{"create": "a"}"#)
            .await
            .unwrap();
        assert_eq!(made["rooms"].as_array().unwrap().len(), 2);
    });
    let served = server.stop();
    assert_eq!((served.opened, served.failed), (3, 0));
    // The second room a recorded beside the first, which is kept.
    assert!(dir.path().join("a-1.mcap").is_file());
}
