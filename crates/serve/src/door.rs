//! What the transport asks of whoever hosts rooms (the registry, `rooms.rs`, implements
//! it): the transport routes a connection to a room by this interface alone, so neither
//! imports the other.

use tokio::sync::oneshot;

use crate::hub::{ClientQueue, Hub};

/// The rooms, as connections see them (`rooms.rs`).
pub trait Door: Send + Sync {
    /// Admits a client with `queue` into room `name`, creating the room if it has none;
    /// or says why not (too many clients, in the room or the server; too many rooms).
    fn enter(&self, name: &str, queue: ClientQueue) -> Result<Entered, String>;
    /// The client left room `hub`.
    fn left(&self, hub: &Hub, client: u64);
    /// `/rooms`: the rooms (making the one asked for), as JSON, or why not.
    fn rooms_call(&self, payload: &[u8]) -> Result<String, String>;
}

/// `/rooms`' id on the plain URL, after the plain server's eight services (on a room's
/// connection it is 3).
pub const PLAIN_ROOMS: u32 = 9;

/// A client admitted into a room.
pub struct Entered {
    /// The room's hub.
    pub hub: Hub,
    /// The client's id there.
    pub id: u64,
    /// Ends the connection when the room closes.
    pub kicked: oneshot::Receiver<String>,
    /// `serverInfo`, `advertise`, `advertiseServices`.
    pub hello: [String; 3],
}

/// A room's name: 1 to [`MAX_ROOM_NAME`] of `A-Z a-z 0-9 _ -`.
pub const MAX_ROOM_NAME: usize = 64;

/// Whether `name` is a room's name, or why not.
pub fn check_room_name(name: &str) -> Result<(), String> {
    let ok = (1..=MAX_ROOM_NAME).contains(&name.len())
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-');
    if ok {
        Ok(())
    } else {
        Err(format!(
            "room name {:?}: 1 to {MAX_ROOM_NAME} of A-Z, a-z, 0-9, _ and -",
            name.chars().take(80).collect::<String>()
        ))
    }
}
