//! `ricochet serve` under hostile connections (issue 20), on loopback, bounded in count and
//! time: half-open sockets under a file-descriptor limit.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::Command;
use std::time::{Duration, Instant};

use crate::serve_client::*;

fn port(url: &str) -> u16 {
    url.rsplit(':').next().unwrap().parse().unwrap()
}

/// User plus system CPU seconds of a process, from /proc/PID/stat.
fn cpu_seconds(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap()
        .split_whitespace()
        .collect();
    let ticks: u64 = fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap();
    // USER_HZ is 100 on every Linux ABI.
    ticks as f64 / 100.0
}

/// Whether the server closed `socket` (EOF or reset), waiting at most until `deadline`.
fn closed_by(socket: &mut TcpStream, deadline: Instant) -> bool {
    let mut buf = [0u8; 512];
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return false;
        }
        socket.set_read_timeout(Some(left)).unwrap();
        match socket.read(&mut buf) {
            Ok(0) => return true,
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => return false,
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => return false,
            Err(_) => return true,
        }
    }
}

// Issue 20: 150 sockets that send half a request and stop exhausted the descriptors; the
// accept loop then spun (a CPU-second a second) and a real client's handshake timed out.
#[test]
fn half_open_sockets_neither_spin_the_server_nor_lock_out_a_real_client() {
    // 24 descriptors: the server uses about 10 of its own, so the sockets run it out of
    // descriptors before the pending handshakes reach their cap.
    let mut command = Command::new("sh");
    command.args([
        "-c",
        "ulimit -n 24 && exec \"$0\" serve --bind 127.0.0.1:0 --paused",
        env!("CARGO_BIN_EXE_ricochet"),
    ]);
    let server = serve_with(command);
    let pid = server.child.id();
    let port = port(&server.url);
    let mut half_open: Vec<TcpStream> = (0..150)
        .map(|_| {
            let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
            s.write_all(b"GET / HTTP/1.1\r\nHost: x\r\n").unwrap();
            s
        })
        .collect();
    let cpu = cpu_seconds(pid);
    std::thread::sleep(Duration::from_secs(2));
    let spent = cpu_seconds(pid) - cpu;
    assert!(spent < 0.5, "{spent} CPU seconds in 2 s, paused");
    runtime().block_on(async {
        let (mut ws, _) = tokio::time::timeout(
            Duration::from_secs(3),
            connect(&server.url, "foxglove.websocket.v1"),
        )
        .await
        .expect("a real client's handshake within 3 s")
        .unwrap();
        assert_eq!(next_json(&mut ws).await["op"], "serverInfo");
    });
    // Each is closed: evicted by newer ones, or after the 5 s handshake timeout.
    let deadline = Instant::now() + Duration::from_secs(8);
    let open = half_open
        .iter_mut()
        .map(|s| closed_by(s, deadline))
        .filter(|closed| !closed)
        .count();
    assert_eq!(open, 0, "half-open sockets still open 8 s on");
}
