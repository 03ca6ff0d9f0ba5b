//! The WebSocket side of `ricochet serve`: accepts connections on a tokio runtime of its own
//! (one thread), negotiates `foxglove.websocket.v1` or `foxglove.sdk.v1`, sends the server
//! info and the channels, and runs each client: its subscriptions in, its queue out.

use std::net::SocketAddr;

use futures_util::{SinkExt, StreamExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::mpsc;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tokio_tungstenite::tungstenite::http::{HeaderValue, StatusCode};

use super::hub::{CLIENT_QUEUE, Hub};
use super::protocol::{self, ClientMessage, ServerMessage};

/// Clients served at once; more are refused (HTTP 503).
pub const MAX_CLIENTS: usize = 64;
/// The largest message a client may send (a subscribe of every channel is a few hundred
/// bytes).
const MAX_CLIENT_MESSAGE: usize = 64 * 1024;

/// Accepts connections on `listener` until the runtime stops.
pub async fn accept(listener: TcpListener, hub: Hub, session: String) {
    loop {
        let Ok((stream, peer)) = listener.accept().await else {
            continue;
        };
        let (hub, session) = (hub.clone(), session.clone());
        tokio::spawn(async move {
            if let Err(e) = client(stream, peer, hub, &session).await {
                tracing_note(&format!("serve: client {peer}: {e}"));
            }
        });
    }
}

/// A line on stderr (lost lines are no failure).
fn tracing_note(text: &str) {
    let _ = crate::out::note(text);
}

/// The handshake's answer: the subprotocol chosen, or HTTP 400 naming the ones accepted.
#[allow(clippy::result_large_err, reason = "tungstenite's callback signature")]
fn negotiate(request: &Request, mut response: Response) -> Result<Response, ErrorResponse> {
    let offered = request
        .headers()
        .get("Sec-WebSocket-Protocol")
        .and_then(|v| v.to_str().ok())
        .unwrap_or("");
    match protocol::choose(offered) {
        Some(chosen) => {
            response
                .headers_mut()
                .insert("Sec-WebSocket-Protocol", HeaderValue::from_static(chosen));
            Ok(response)
        }
        None => {
            let mut refusal = ErrorResponse::new(Some(format!(
                "this is a Foxglove WebSocket server: offer one of the subprotocols {}",
                protocol::SUBPROTOCOLS.join(", ")
            )));
            *refusal.status_mut() = StatusCode::BAD_REQUEST;
            Err(refusal)
        }
    }
}

async fn client(
    stream: TcpStream,
    peer: SocketAddr,
    hub: Hub,
    session: &str,
) -> Result<(), String> {
    let config = tokio_tungstenite::tungstenite::protocol::WebSocketConfig::default()
        .max_message_size(Some(MAX_CLIENT_MESSAGE))
        .max_frame_size(Some(MAX_CLIENT_MESSAGE));
    let ws = tokio_tungstenite::accept_hdr_async_with_config(stream, negotiate, Some(config))
        .await
        .map_err(|e| format!("handshake: {e}"))?;
    let (mut out, mut incoming) = ws.split();
    let (queue, mut pending) = mpsc::channel::<Message>(CLIENT_QUEUE);
    let admitted = {
        let mut s = hub.lock();
        (s.client_count() < MAX_CLIENTS).then(|| {
            let info = ServerMessage::ServerInfo {
                name: "ricochet",
                capabilities: &["time", "clientPublish", "services", "playbackControl"],
                supported_encodings: &["json"],
                metadata: Default::default(),
                session_id: session,
                data_start_time: protocol::Time::from_ns(0),
                data_end_time: protocol::Time::from_ns(s.data_end_ns),
            };
            let advertise = ServerMessage::Advertise {
                channels: s.channels(),
            };
            let services = ServerMessage::AdvertiseServices {
                services: &super::services::list(),
            };
            let hello = [info.json(), advertise.json(), services.json()];
            (s.connect(queue.clone()), hello)
        })
    };
    let Some((id, hello)) = admitted else {
        let status = ServerMessage::Status {
            level: 2,
            message: "too many clients",
        };
        let _ = out.send(Message::text(status.json())).await;
        return Err("refused: too many clients".to_owned());
    };
    tracing_note(&format!("serve: client {peer} connected"));
    let mut limit = RateLimit::new();
    let result = async {
        for text in hello {
            out.send(Message::text(text))
                .await
                .map_err(|e| e.to_string())?;
        }
        loop {
            tokio::select! {
                sent = pending.recv() => match sent {
                    Some(m) => out.send(m).await.map_err(|e| e.to_string())?,
                    None => return Ok(()),
                },
                got = incoming.next() => match got {
                    None | Some(Ok(Message::Close(_))) => return Ok(()),
                    Some(Err(e)) => return Err(e.to_string()),
                    Some(Ok(Message::Text(text))) => {
                        if let Err(why) = handle(&hub, id, text.as_str()) {
                            let status = ServerMessage::Status { level: 2, message: &why };
                            let _ = queue.try_send(Message::text(status.json()));
                        }
                    }
                    Some(Ok(Message::Binary(data))) => {
                        if let Err(why) = publish(&hub, id, &data, &mut limit) {
                            let status = ServerMessage::Status { level: 2, message: &why };
                            let _ = queue.try_send(Message::text(status.json()));
                        }
                    }
                    Some(Ok(_)) => {}
                },
            }
        }
    }
    .await;
    hub.lock().disconnect(id);
    tracing_note(&format!("serve: client {peer} disconnected"));
    result
}

/// One JSON message from a client; an error is told to it as a status message.
fn handle(hub: &Hub, client: u64, text: &str) -> Result<(), String> {
    let message: ClientMessage =
        serde_json::from_str(text).map_err(|e| format!("unsupported or malformed message: {e}"))?;
    let mut s = hub.lock();
    match message {
        ClientMessage::Subscribe { subscriptions } => {
            for sub in subscriptions {
                s.subscribe(client, sub.id, sub.channel_id)?;
            }
        }
        ClientMessage::Unsubscribe { subscription_ids } => s.unsubscribe(client, &subscription_ids),
        ClientMessage::Advertise { channels } => {
            for c in channels {
                s.advertise(client, c.id, &c.topic, &c.encoding);
            }
        }
        ClientMessage::Unadvertise { channel_ids } => s.unadvertise(client, &channel_ids),
    }
    Ok(())
}

/// Inputs a client may send per second; beyond, they are refused (and it is told).
pub const MAX_INPUTS_PER_SECOND: f64 = 2000.0;

/// A token bucket over the wall clock (which only paces: it never reaches the session).
struct RateLimit {
    tokens: f64,
    at: std::time::Instant,
}

impl RateLimit {
    fn new() -> RateLimit {
        RateLimit {
            tokens: MAX_INPUTS_PER_SECOND,
            at: std::time::Instant::now(),
        }
    }

    fn take(&mut self) -> bool {
        let now = std::time::Instant::now();
        let refill = now.duration_since(self.at).as_secs_f64() * MAX_INPUTS_PER_SECOND;
        self.tokens = (self.tokens + refill).min(MAX_INPUTS_PER_SECOND);
        self.at = now;
        if self.tokens >= 1.0 {
            self.tokens -= 1.0;
            true
        } else {
            false
        }
    }
}

/// A binary message from a client: an input on its `/input` channel, or a service call.
fn publish(hub: &Hub, client: u64, data: &[u8], limit: &mut RateLimit) -> Result<(), String> {
    if data.first() == Some(&protocol::OP_SERVICE_CALL) {
        let call = protocol::service_call(data)?;
        return hub.lock().call(client, call);
    }
    if data.first() == Some(&protocol::OP_PLAYBACK_CONTROL) {
        let request = protocol::playback_control(data)?;
        let mut s = hub.lock();
        if s.playback.len() >= 64 {
            return Err("too many playback requests waiting".to_owned());
        }
        s.playback.push_back((client, request));
        return Ok(());
    }
    if data.len() < 5 || data[0] != protocol::OP_CLIENT_MESSAGE {
        return Err(
            "a binary message that is neither a client message (opcode 1) nor a service call (2)"
                .to_owned(),
        );
    }
    if !limit.take() {
        return Err(format!(
            "input refused: more than {MAX_INPUTS_PER_SECOND} inputs a second"
        ));
    }
    let channel = u32::from_le_bytes([data[1], data[2], data[3], data[4]]);
    hub.lock().input(client, channel, &data[5..])
}
