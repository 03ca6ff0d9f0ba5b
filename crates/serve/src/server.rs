//! The WebSocket side of `ricochet serve`: accepts connections on a tokio runtime of its own
//! (one thread), negotiates `foxglove.websocket.v1` or `foxglove.sdk.v1`, sends the server
//! info and the channels, and runs each client: its subscriptions in, its queue out.
//!
//! A connection costs memory and a file descriptor from its first byte, so the handshakes
//! are bounded too: at most [`MAX_PENDING_HANDSHAKES`] at once (a new one evicts the
//! oldest, so sockets that stop mid-request never lock out a real client), each at most
//! [`HANDSHAKE_TIMEOUT`]. Running out of file descriptors backs the accept loop off.

use std::collections::VecDeque;
use std::net::SocketAddr;
use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::oneshot;
use tokio_tungstenite::WebSocketStream;
use tokio_tungstenite::tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tokio_tungstenite::tungstenite::http::{HeaderValue, StatusCode};
use tokio_tungstenite::tungstenite::protocol::CloseFrame;
use tokio_tungstenite::tungstenite::protocol::frame::coding::CloseCode;
use tokio_tungstenite::tungstenite::{Error as WsError, Message};

use std::sync::Arc;

use crate::common::{MAX_CLIENTS, Note, metadata};
use crate::door::{Door, PLAIN_ROOMS, check_room_name};
use crate::hub::{ClientQueue, Hub, client_queue};
use crate::protocol::{self, ClientMessage, ServerMessage};

/// The largest message a client may send (a subscribe of every channel is a few hundred
/// bytes). A larger one closes the connection with status 1009 (Message Too Big) and a
/// reason naming the limit.
pub const MAX_CLIENT_MESSAGE: usize = 64 * 1024;

/// A connection's read buffer, bytes (tungstenite's default is 128 KiB, zeroed before
/// every read).
const READ_BUFFER: usize = 4096;

/// Queued messages written to a client with one flush, at most: the connection reads its
/// client between batches.
const MAX_BATCH: usize = 64;

/// How long a connection the server closes (a message too big, too many clients) is still
/// read, what comes dropped, after the close frame: so that the kernel ends it with a FIN
/// rather than a reset, which could discard the close frame before the client reads it.
const CLOSE_LINGER: Duration = Duration::from_secs(1);
/// Connections lingering at once (a socket each, for at most [`CLOSE_LINGER`]); past them,
/// one is closed at once after its close frame, so a flood of clients past the cap holds no
/// more sockets than before.
const MAX_LINGERING: usize = 32;
/// Connections lingering now.
static LINGERING: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Handshakes under way at once (each holds a socket and at most tungstenite's 64 KiB of
/// request); a connection past them evicts the oldest.
pub const MAX_PENDING_HANDSHAKES: usize = 32;
/// How long a handshake may take from the connection (a browser on a LAN takes
/// milliseconds).
pub const HANDSHAKE_TIMEOUT: Duration = Duration::from_secs(5);
/// The pause after a failed accept (out of file descriptors, mostly): the listener stays
/// readable then, so retrying at once would spin.
const ACCEPT_BACKOFF: Duration = Duration::from_millis(100);

/// Where connections go, by their URL's path: `/rooms/NAME` to the rooms (if the server
/// hosts rooms), any other path to the plain server's single session (if there is one).
#[derive(Clone)]
pub struct Routes {
    /// The single session's hub and its id for `serverInfo`.
    pub plain: Option<(Hub, String)>,
    /// The rooms.
    pub rooms: Option<Arc<dyn Door>>,
}

/// Where a connection goes.
#[derive(Clone, Debug)]
enum Route {
    Plain,
    Room(String),
}

/// The route of a request's path, or why it has none.
fn route(routes: &Routes, path: &str) -> Result<Route, String> {
    let rooms = path == "/rooms" || path.starts_with("/rooms/");
    if !rooms {
        return match routes.plain {
            Some(_) => Ok(Route::Plain),
            None => Err("this server hosts rooms: connect to /rooms/NAME".to_owned()),
        };
    }
    if routes.rooms.is_none() {
        return Err("this server hosts no rooms".to_owned());
    }
    let name = path.strip_prefix("/rooms/").unwrap_or("");
    check_room_name(name)?;
    Ok(Route::Room(name.to_owned()))
}

/// Accepts connections on `listener` until the runtime stops.
pub async fn accept(listener: TcpListener, routes: Routes, note: Note) {
    // The handshakes under way, oldest first: dropping one's sender evicts it; a finished
    // one has dropped its receiver.
    let mut pending: VecDeque<oneshot::Sender<()>> = VecDeque::new();
    let mut failing = false;
    loop {
        let (stream, peer) = match listener.accept().await {
            Ok(accepted) => accepted,
            Err(e) => {
                if !failing {
                    note(&format!("serve: accepting a connection: {e}"));
                }
                failing = true;
                pending.retain(|p| !p.is_closed());
                // Out of descriptors, mostly: the oldest handshake gives its back (its task
                // closes the socket when it runs next); with none, the clients hold them
                // all, and only waiting helps.
                if pending.pop_front().is_some() {
                    tokio::task::yield_now().await;
                } else {
                    tokio::time::sleep(ACCEPT_BACKOFF).await;
                }
                continue;
            }
        };
        failing = false;
        pending.retain(|p| !p.is_closed());
        if pending.len() >= MAX_PENDING_HANDSHAKES {
            pending.pop_front();
        }
        let (evict, evicted) = oneshot::channel();
        pending.push_back(evict);
        let (routes, note) = (routes.clone(), note.clone());
        tokio::spawn(async move {
            if let Err(e) = client(stream, peer, routes, evicted, &note).await {
                note(&format!("serve: client {peer}: {e}"));
            }
        });
    }
}

/// The handshake's answer: the subprotocol chosen, or HTTP 400 naming the ones accepted;
/// or HTTP 400 naming why the path is no room's (`route`'s error).
#[allow(clippy::result_large_err, reason = "tungstenite's callback signature")]
fn negotiate(
    routes: &Routes,
    chosen_route: &std::sync::Mutex<Option<Route>>,
    request: &Request,
    mut response: Response,
) -> Result<Response, ErrorResponse> {
    match route(routes, request.uri().path()) {
        Ok(r) => {
            *chosen_route
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner) = Some(r);
        }
        Err(why) => {
            let mut refusal = ErrorResponse::new(Some(why));
            *refusal.status_mut() = StatusCode::BAD_REQUEST;
            return Err(refusal);
        }
    }
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
    routes: Routes,
    evicted: oneshot::Receiver<()>,
    note: &Note,
) -> Result<(), String> {
    // tungstenite zeroes its whole free read buffer before each read (128 KiB by default):
    // with hundreds of connections each reading a few small inputs a second, that memset
    // was most of this thread's time (BENCHMARKS.md, "Rooms"), and 128 KiB resident per
    // client. A client's messages are small (inputs, calls); a larger one grows the buffer.
    let config = tokio_tungstenite::tungstenite::protocol::WebSocketConfig::default()
        .read_buffer_size(READ_BUFFER)
        .max_message_size(Some(MAX_CLIENT_MESSAGE))
        .max_frame_size(Some(MAX_CLIENT_MESSAGE));
    let chosen = std::sync::Mutex::new(None);
    #[allow(clippy::result_large_err, reason = "tungstenite's callback signature")]
    let callback =
        |request: &Request, response: Response| negotiate(&routes, &chosen, request, response);
    let handshake = tokio_tungstenite::accept_hdr_async_with_config(stream, callback, Some(config));
    let ws = tokio::select! {
        done = tokio::time::timeout(HANDSHAKE_TIMEOUT, handshake) => match done {
            Ok(ws) => ws.map_err(|e| format!("handshake: {e}"))?,
            Err(_) => return Err(format!(
                "handshake: not finished within {} s, closed", HANDSHAKE_TIMEOUT.as_secs()
            )),
        },
        _ = evicted => return Err(format!(
            "handshake: closed unfinished, {MAX_PENDING_HANDSHAKES} newer connections came"
        )),
    };
    let (mut out, mut incoming) = ws.split();
    let (queue, mut pending) = client_queue();
    let route = chosen
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let (admitted, door) = match (route, &routes.plain, &routes.rooms) {
        (Some(Route::Room(name)), _, Some(door)) => match door.enter(&name, queue.clone()) {
            Ok(e) => (Ok((e.hub, e.id, e.kicked, e.hello)), Some(door)),
            Err(why) => (Err((why.clone(), why)), None),
        },
        (_, Some((hub, session)), rooms) => (plain(hub, session, &queue, rooms.is_some()), None),
        // The handshake refused any other route.
        _ => return Err("no route".to_owned()),
    };
    let (hub, id, mut kicked, hello) = match admitted {
        Ok(a) => a,
        Err((status, why)) => {
            let status = ServerMessage::Status {
                level: 2,
                message: &status,
            };
            let frame = CloseFrame {
                code: CloseCode::Again,
                reason: why.clone().into(),
            };
            if let Ok(ws) = out.reunite(incoming) {
                close_with(ws, Some(Message::text(status.json())), frame).await;
            }
            return Err(format!("refused: {why}; closed with 1013"));
        }
    };
    note(&format!("serve: client {peer} connected"));
    let mut limit = RateLimit::new();
    let result = async {
        for text in hello {
            out.send(Message::text(text))
                .await
                .map_err(|e| Ended::Failed(e.to_string()))?;
        }
        loop {
            tokio::select! {
                sent = pending.recv() => match sent {
                    Some(m) => {
                        // What else is queued goes in the same write (a frame's `time` and
                        // its messages): one system call, not one a message.
                        out.feed(m).await.map_err(|e| Ended::Failed(e.to_string()))?;
                        for _ in 1..MAX_BATCH {
                            // Paced as `recv` is: `try_recv` is for a closing connection.
                            let Some(m) = pending.ready() else { break };
                            out.feed(m).await.map_err(|e| Ended::Failed(e.to_string()))?;
                        }
                        out.flush().await.map_err(|e| Ended::Failed(e.to_string()))?;
                    }
                    None => return Ok(()),
                },
                Ok(why) = &mut kicked => {
                    // What was queued before (the status saying why) goes first.
                    while let Ok(m) = pending.try_recv() {
                        out.send(m).await.map_err(|e| Ended::Failed(e.to_string()))?;
                    }
                    return Err(Ended::Closed(why));
                }
                got = incoming.next() => match got {
                    None | Some(Ok(Message::Close(_))) => return Ok(()),
                    Some(Err(WsError::Capacity(e))) => return Err(Ended::TooBig(e.to_string())),
                    Some(Err(e)) => return Err(Ended::Failed(e.to_string())),
                    Some(Ok(Message::Text(text))) => {
                        if let Err(why) = handle(&hub, id, text.as_str()) {
                            let status = ServerMessage::Status { level: 2, message: &why };
                            let _ = queue.answer(Message::text(status.json()));
                        }
                    }
                    Some(Ok(Message::Binary(data))) => {
                        // `/rooms` on the plain URL: answered here, not by the session's loop.
                        let plain_rooms = routes.plain.is_some() && door.is_none()
                            && data.first() == Some(&protocol::OP_SERVICE_CALL);
                        if let (true, Some(rooms)) = (plain_rooms, &routes.rooms)
                            && let Ok(call) = protocol::service_call(&data)
                            && call.service == PLAIN_ROOMS
                        {
                            hub.lock().answer(id, call.service, call.call, rooms.rooms_call(&call.payload));
                            continue;
                        }
                        if let Err(why) = publish(&hub, id, &data, &mut limit) {
                            let status = ServerMessage::Status { level: 2, message: &why };
                            let _ = queue.answer(Message::text(status.json()));
                        }
                    }
                    Some(Ok(_)) => {}
                },
            }
        }
    }
    .await;
    hub.lock().disconnect(id);
    if let Some(door) = door {
        door.left(&hub, id);
    }
    // Nothing more is sent to it: the queue's messages are dropped with it.
    drop(pending);
    let result = match result {
        Ok(()) => Ok(()),
        Err(Ended::Failed(e)) => Err(e),
        Err(Ended::Closed(why)) => {
            let frame = CloseFrame {
                code: CloseCode::Away,
                reason: why.chars().take(120).collect::<String>().into(),
            };
            if let Ok(ws) = out.reunite(incoming) {
                close_with(ws, None, frame).await;
            }
            Ok(())
        }
        Err(Ended::TooBig(e)) => {
            let frame = CloseFrame {
                code: CloseCode::Size,
                reason: format!("message over {} KiB", MAX_CLIENT_MESSAGE / 1024).into(),
            };
            if let Ok(ws) = out.reunite(incoming) {
                close_with(ws, None, frame).await;
            }
            Err(format!(
                "{e}: closed with 1009, the most a client may send is {} KiB",
                MAX_CLIENT_MESSAGE / 1024
            ))
        }
    };
    note(&format!("serve: client {peer} disconnected"));
    result
}

/// Admits a client to the plain server's session, or says why not (the status, the close
/// frame's reason).
#[allow(clippy::type_complexity, reason = "one use")]
fn plain(
    hub: &Hub,
    session: &str,
    queue: &ClientQueue,
    rooms: bool,
) -> Result<(Hub, u64, oneshot::Receiver<String>, [String; 3]), (String, String)> {
    let mut s = hub.lock();
    if s.client_count() >= MAX_CLIENTS {
        return Err((
            "too many clients".to_owned(),
            format!("too many clients, at most {MAX_CLIENTS}"),
        ));
    }
    let info = ServerMessage::ServerInfo {
        name: "ricochet",
        capabilities: &["time", "clientPublish", "services", "playbackControl"],
        supported_encodings: &["json"],
        metadata: metadata(),
        session_id: session,
        data_start_time: protocol::Time::from_ns(0),
        data_end_time: protocol::Time::from_ns(s.data_end_ns),
    };
    let advertise = ServerMessage::Advertise {
        channels: s.channels(),
    };
    let mut list = crate::services::list();
    if rooms {
        let mut service = crate::room::services().swap_remove(2);
        service.id = PLAIN_ROOMS;
        list.push(service);
    }
    let services = ServerMessage::AdvertiseServices { services: &list };
    let hello = [info.json(), advertise.json(), services.json()];
    let (id, kicked) = s.connect(queue.clone());
    Ok((hub.clone(), id, kicked, hello))
}

/// Why a client's connection ended, but for its closing it.
enum Ended {
    /// The room closed (why).
    Closed(String),
    /// A message over [`MAX_CLIENT_MESSAGE`] (tungstenite's words).
    TooBig(String),
    /// Reading or writing failed.
    Failed(String),
}

/// Closes `ws` saying why: `last` if any, then `frame` (1009 for a message over
/// [`MAX_CLIENT_MESSAGE`], 1013 past [`MAX_CLIENTS`]); then what the client still sends is
/// read and dropped, at most for [`CLOSE_LINGER`], until it closes too.
async fn close_with(mut ws: WebSocketStream<TcpStream>, last: Option<Message>, frame: CloseFrame) {
    let linger = async {
        if let Some(m) = last
            && ws.send(m).await.is_err()
        {
            return;
        }
        if ws.close(Some(frame)).await.is_err() {
            return;
        }
        let mut stream = ws.into_inner();
        // A FIN after the close frame; what the client sent may still be unread.
        let shut = std::future::poll_fn(|cx| {
            tokio::io::AsyncWrite::poll_shutdown(std::pin::Pin::new(&mut stream), cx)
        });
        if shut.await.is_err() {
            return;
        }
        use std::sync::atomic::Ordering::AcqRel;
        if LINGERING.fetch_add(1, AcqRel) >= MAX_LINGERING {
            LINGERING.fetch_sub(1, AcqRel);
            return;
        }
        // Given back however the linger ends (the timeout drops this future).
        struct Lingering;
        impl Drop for Lingering {
            fn drop(&mut self) {
                LINGERING.fetch_sub(1, std::sync::atomic::Ordering::AcqRel);
            }
        }
        let _lingering = Lingering;
        let mut buf = [0u8; 4096];
        loop {
            if stream.readable().await.is_err() {
                return;
            }
            match stream.try_read(&mut buf) {
                Ok(0) => return,
                Ok(_) => {}
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
                Err(_) => return,
            }
        }
    };
    let _ = tokio::time::timeout(CLOSE_LINGER, linger).await;
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
                s.advertise(client, c.id, &c.topic, &c.encoding)?;
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
