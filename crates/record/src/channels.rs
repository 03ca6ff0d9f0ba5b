//! Which channels a run records (`ricochet run --channels`). A headless golden-log run may
//! leave `/scene` out (the largest channel); Foxglove then shows no 3D scene, but plots and
//! the log panel still work from `/stats` and `/events`, and `ricochet diff` compares what
//! both logs hold.

use std::fmt;

/// The channels to record; all five by default.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Channels {
    /// `/scene`, `/scene/static`, `/tf` and `/scene/contacts`: the 3D panel's drawing.
    pub scene: bool,
    /// `/bodies`: every body's exact state.
    pub bodies: bool,
    /// `/contacts`: every contact with its poses.
    pub contacts: bool,
    /// `/stats`: the per-frame counters.
    pub stats: bool,
    /// `/events`: inputs, spawns, destructions, collisions.
    pub events: bool,
}

/// The channel names `--channels` takes, in log order.
pub const NAMES: [&str; 5] = ["scene", "bodies", "contacts", "stats", "events"];

impl Default for Channels {
    fn default() -> Self {
        Channels {
            scene: true,
            bodies: true,
            contacts: true,
            stats: true,
            events: true,
        }
    }
}

/// A `--channels` value that names no known channel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownChannel(pub String);

impl fmt::Display for UnknownChannel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "--channels: unknown channel {:?}; the channels are {}",
            self.0,
            NAMES.join(", ")
        )
    }
}

impl std::error::Error for UnknownChannel {}

impl Channels {
    /// Parses a comma-separated list of channel names, with or without the leading `/`
    /// (`bodies,contacts,events` or `/bodies,/events`). An empty list records nothing but
    /// the log's header and summary.
    pub fn parse(list: &str) -> Result<Channels, UnknownChannel> {
        let mut c = Channels {
            scene: false,
            bodies: false,
            contacts: false,
            stats: false,
            events: false,
        };
        for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            let flag = match name.trim_start_matches('/') {
                "scene" => &mut c.scene,
                "bodies" => &mut c.bodies,
                "contacts" => &mut c.contacts,
                "stats" => &mut c.stats,
                "events" => &mut c.events,
                _ => return Err(UnknownChannel(name.to_owned())),
            };
            *flag = true;
        }
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_list_names_the_channels_with_or_without_a_slash() {
        let c = Channels::parse("bodies, /contacts,events").unwrap();
        assert_eq!(
            (c.scene, c.bodies, c.contacts, c.stats, c.events),
            (false, true, true, false, true)
        );
        assert_eq!(
            Channels::parse("bodys"),
            Err(UnknownChannel("bodys".to_owned()))
        );
    }
}
