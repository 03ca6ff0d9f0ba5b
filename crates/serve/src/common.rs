//! What every layer of the server shares, at the bottom of its imports: where notes go,
//! the listener, the errors, the lateness histogram and a few bounds.

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use ricochet_log::LogError;
use ricochet_record::session::StepError;

/// Where `serve` listens unless told: what Foxglove's "Open connection" suggests.
pub const DEFAULT_BIND: &str = "127.0.0.1:8765";

/// Simulation seconds per wall second a server may run at (`--speed`, `/speed`, the
/// timeline): a frame's wait, dt / speed, stays a duration (1e-300 made it infinite, and
/// the loop panicked).
pub const SPEEDS: std::ops::RangeInclusive<f64> = 0.01..=100.0;

/// Clients served at once; more are told so (a status) and closed with 1013 (Try Again
/// Later). In rooms, the cap of each room; a rooms server's whole cap is
/// [`crate::RoomOptions::max_clients`].
pub const MAX_CLIENTS: usize = 64;

/// Where the server's notes go (a client connected, a frame overflowed, how late frames
/// were): a line each, without a newline. Losing one is no failure.
pub type Note = Arc<dyn Fn(&str) + Send + Sync>;

/// Why serving failed or could not start.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// An option is out of range.
    #[error("{0}")]
    Options(String),
    /// The address could not be listened on.
    #[error("cannot listen on {addr}: {source}")]
    Bind {
        /// The address asked for.
        addr: SocketAddr,
        /// Why.
        source: std::io::Error,
    },
    /// The WebSocket runtime or its thread could not start.
    #[error("starting the WebSocket server: {0}")]
    Runtime(std::io::Error),
    /// Writing the recording (or the live stream's bookkeeping) failed.
    #[error(transparent)]
    Log(#[from] LogError),
    /// Recording a frame failed.
    #[error(transparent)]
    Step(#[from] StepError),
}

/// A bound WebSocket listener, not serving yet (so the caller can say where it listens).
pub struct Listener {
    pub(crate) runtime: tokio::runtime::Runtime,
    pub(crate) listener: tokio::net::TcpListener,
    local: SocketAddr,
}

impl Listener {
    /// Listens on `addr` (port 0: any free port).
    pub fn bind(addr: SocketAddr) -> Result<Listener, ServeError> {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .map_err(ServeError::Runtime)?;
        let listener = runtime
            .block_on(tokio::net::TcpListener::bind(addr))
            .map_err(|source| ServeError::Bind { addr, source })?;
        let local = listener
            .local_addr()
            .map_err(|source| ServeError::Bind { addr, source })?;
        Ok(Listener {
            runtime,
            listener,
            local,
        })
    }

    /// The address it listens on (the port chosen, for port 0).
    pub fn local_addr(&self) -> SocketAddr {
        self.local
    }
}

/// How late frames start, in a fixed histogram (bounded memory however long the server
/// runs): 0.05 ms buckets up to 100 ms, then one for all later.
pub(crate) struct Lateness {
    buckets: [u64; 2001],
    count: u64,
    max_ms: f64,
}

impl Default for Lateness {
    fn default() -> Self {
        Lateness {
            buckets: [0; 2001],
            count: 0,
            max_ms: 0.0,
        }
    }
}

impl Lateness {
    /// Adds `other`'s counts.
    pub(crate) fn merge(&mut self, other: &Lateness) {
        for (a, b) in self.buckets.iter_mut().zip(other.buckets.iter()) {
            *a += b;
        }
        self.count += other.count;
        self.max_ms = self.max_ms.max(other.max_ms);
    }

    /// The latest, ms.
    pub(crate) fn max_ms(&self) -> f64 {
        self.max_ms
    }

    pub(crate) fn add(&mut self, late: Duration) {
        let ms = late.as_secs_f64() * 1e3;
        let bucket = ((ms / 0.05) as usize).min(self.buckets.len() - 1);
        self.buckets[bucket] += 1;
        self.count += 1;
        self.max_ms = self.max_ms.max(ms);
    }

    /// The `q` quantile, ms (the upper edge of its bucket).
    pub(crate) fn quantile(&self, q: f64) -> f64 {
        let want = (q * self.count as f64).ceil() as u64;
        let mut seen = 0;
        for (i, n) in self.buckets.iter().enumerate() {
            seen += n;
            if seen >= want.max(1) {
                return ((i + 1) as f64 * 0.05).min(self.max_ms);
            }
        }
        self.max_ms
    }
}

/// The server's metadata: `ROS_DISTRO`, because Lichtblick's (and Foxglove Studio's) 3D
/// panel offers its publish tools ("Publish point": `/clicked_point`, `click.rs`) only to
/// a ROS data source, which it recognises by that key. Any value but a ROS 1 distro makes
/// it a ROS 2 source; `humble` picks the message definitions it ships for that. Ricochet
/// speaks no ROS otherwise: every channel stays protobuf, every schema Foxglove's or its own.
pub(crate) fn metadata() -> std::collections::BTreeMap<String, String> {
    [("ROS_DISTRO".to_owned(), "humble".to_owned())].into()
}
