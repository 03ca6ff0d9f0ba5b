//! `ricochet_serve::serve` on the level of `examples/serve_game.rs`: a client on 127.0.0.1
//! connects, publishes a thrust on `/input`, and the input lands: the recording holds it at
//! the frame it applied to, the ship is still before that frame and moving from it on.

use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use serde_json::Value;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;

#[path = "../examples/shared/my_asteroids.rs"]
mod my_asteroids;

/// Frames served (after frame 0) and the pace: 240 frames at 4x, one second.
const FRAMES: u64 = 240;

/// The next JSON message, waiting at most 10 s.
async fn next_json<S>(ws: &mut S) -> Value
where
    S: StreamExt<Item = Result<Message, tokio_tungstenite::tungstenite::Error>> + Unpin,
{
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .expect("a message within 10 s")
            .expect("the connection open")
            .unwrap();
        if let Message::Text(t) = m {
            return serde_json::from_str(t.as_str()).unwrap();
        }
    }
}

#[test]
fn a_clients_input_lands_and_is_recorded_at_its_frame() {
    let dir = tempfile::tempdir().unwrap();
    let record = dir.path().join("served.mcap");
    let notes = Arc::new(Mutex::new(Vec::<String>::new()));
    let kept = notes.clone();
    let options = ricochet_serve::Options {
        frames: Some(FRAMES),
        speed: 4.0,
        record: Some(record.clone()),
        note: Arc::new(move |t: &str| kept.lock().unwrap().push(t.to_owned())),
        ..Default::default()
    };
    let listener = ricochet_serve::Listener::bind("127.0.0.1:0".parse().unwrap()).unwrap();
    let url = format!("ws://{}", listener.local_addr());
    let server = std::thread::spawn(move || {
        let stop = AtomicBool::new(false);
        let level = my_asteroids::level().unwrap();
        ricochet_serve::serve(listener, level, String::new(), &options, &stop)
    });
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let mut request = url.as_str().into_client_request().unwrap();
        request.headers_mut().insert(
            "Sec-WebSocket-Protocol",
            "foxglove.websocket.v1".parse().unwrap(),
        );
        let (mut ws, _) = tokio_tungstenite::connect_async(request).await.unwrap();
        let info = next_json(&mut ws).await;
        assert_eq!(info["op"], "serverInfo", "{info}");
        let advertise = serde_json::json!({"op": "advertise", "channels": [
            {"id": 5, "topic": "/input", "encoding": "json", "schemaName": "ricochet.Input"}]});
        ws.send(Message::text(advertise.to_string())).await.unwrap();
        let mut data = vec![1u8];
        data.extend_from_slice(&5u32.to_le_bytes());
        data.extend_from_slice(br#"{"action": "thrust", "body": "ship", "on": true}"#);
        ws.send(Message::binary(data)).await.unwrap();
        // Stay connected while the server runs on (the input applies at a frame boundary).
        tokio::time::sleep(Duration::from_millis(200)).await;
    });
    let served = server.join().unwrap().unwrap();
    assert_eq!(served.next_frame, FRAMES + 1);
    let notes = notes.lock().unwrap();
    assert!(notes.iter().any(|n| n.contains("connected")), "{notes:?}");

    let log = ricochet_log::read_log_file(&record).unwrap();
    let inputs: Vec<_> = log.iter().filter(|m| m.topic == "/input").collect();
    assert_eq!(inputs.len(), 1, "the one input, recorded");
    let input = &inputs[0].data;
    assert!(
        input["text"].as_str().unwrap().contains("thrust"),
        "{input}"
    );
    let applied = input["frame"].as_u64().unwrap();
    let dt_ns = (my_asteroids::level().unwrap().world.dt * 1e9).round() as u64;
    assert_eq!(inputs[0].log_time, applied * dt_ns, "{input}");
    assert!(
        applied > 0 && applied <= FRAMES,
        "applied at frame {applied}"
    );
    // The ship (heading +x, at rest) moves from the input's frame on, and not before.
    let mut states = ricochet_log::BodyStates::default();
    for (frame, m) in log.iter().filter(|m| m.topic == "/bodies").enumerate() {
        let all = states.apply(&m.data);
        let ship = all["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .find(|b| b["name"] == "ship")
            .unwrap()
            .clone();
        let vx = ship["velocity"][0].as_f64().unwrap();
        if (frame as u64) < applied {
            assert_eq!(vx, 0.0, "frame {frame}: still before the input");
        } else {
            assert!(vx > 0.0, "frame {frame}: thrusting, {ship}");
        }
    }
}
