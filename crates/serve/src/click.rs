//! Clicked points: what Lichtblick's 3D panel publishes with its "Publish point" tool, and
//! the `/events` line that answers one.
//!
//! The 3D panel advertises `/clicked_point` (its default point topic, and the layout's)
//! with schema name `geometry_msgs/PointStamped` in the first encoding the server lists
//! (`json` here), and sends each click as that message in JSON:
//! `{"header": {"stamp": {"sec": S, "nsec": N}, "frame_id": "view"}, "point": {"x": X, "y":
//! Y, "z": 0}}`, the point in the panel's display frame (the layout follows `view`). Its
//! publish tools show only for a ROS data source, which Lichtblick recognises by a
//! `ROS_DISTRO` in the server's metadata (`server.rs`).
//!
//! A click is a question, not an input: it changes nothing in the simulation, so it is
//! answered live (the bodies at the point, each with its whole state, on `/events`) and
//! never recorded. The recording, and so `ricochet replay`, stays the same bytes whatever
//! was clicked.

use ricochet_geom::{MAX_COORDINATE, Vec2};
use serde::Deserialize;

use ricochet_record::scene::{VIEW, WORLD};

/// `geometry_msgs/PointStamped` as Lichtblick writes it in JSON (a ROS 1 `seq`, or other
/// fields, are ignored).
#[derive(Deserialize)]
struct PointStamped {
    header: Header,
    point: Point,
}

#[derive(Deserialize)]
struct Header {
    frame_id: String,
}

#[derive(Deserialize)]
struct Point {
    x: f64,
    y: f64,
}

/// A clicked point: its coordinates and the frame they are in.
#[derive(Debug, Clone, PartialEq)]
pub struct Click {
    /// The point, in `frame`.
    pub point: Vec2,
    /// `world` or `view`, Ricochet's two frames.
    pub frame: Frame,
}

/// The frames a click may be given in: those Ricochet's messages use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Frame {
    /// The scene's frame.
    World,
    /// The camera's, on `/tf`: `world` moved to where the view looks.
    View,
}

/// Reads a clicked point's JSON, or says why it is refused.
pub fn parse(payload: &[u8]) -> Result<Click, String> {
    let m: PointStamped = serde_json::from_slice(payload)
        .map_err(|e| format!("clicked point refused: not a geometry_msgs/PointStamped: {e}"))?;
    let point = Vec2::new(m.point.x, m.point.y);
    if !(point.is_finite() && point.abs().max_element() <= MAX_COORDINATE) {
        return Err(format!(
            "clicked point refused: its x and y must be finite and within ±{MAX_COORDINATE:e}"
        ));
    }
    let frame = match m.header.frame_id.as_str() {
        WORLD => Frame::World,
        VIEW => Frame::View,
        other => {
            return Err(format!(
                "clicked point refused: frame {other:?} is not one of Ricochet's ({WORLD:?}, \
                 {VIEW:?}): set the 3D panel's display frame to one of them"
            ));
        }
    };
    Ok(Click { point, frame })
}

impl Click {
    /// The point in `world`, with the `view` frame's origin at `view`.
    pub fn in_world(&self, view: Vec2) -> Vec2 {
        match self.frame {
            Frame::World => self.point,
            Frame::View => self.point + view,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The message as Lichtblick's `makePointMessage` builds it (ROS 2: no `seq`).
    #[test]
    fn lichtblicks_point_message_is_read_in_either_frame() {
        let click = parse(
            br#"{"header":{"stamp":{"sec":1764745200,"nsec":5000000},"frame_id":"view"},"point":{"x":1.5,"y":-2,"z":0}}"#,
        )
        .unwrap();
        assert_eq!(click.frame, Frame::View);
        assert_eq!(click.in_world(Vec2::new(10.0, 20.0)), Vec2::new(11.5, 18.0));
        let world =
            parse(br#"{"header":{"seq":3,"stamp":{"sec":0,"nsec":0},"frame_id":"world"},"point":{"x":4,"y":5,"z":0}}"#)
                .unwrap();
        assert_eq!(world.in_world(Vec2::new(10.0, 20.0)), Vec2::new(4.0, 5.0));
        for bad in [
            &br#"{"header":{"frame_id":"map"},"point":{"x":0,"y":0,"z":0}}"#[..],
            br#"{"header":{"frame_id":"world"},"point":{"x":1e999,"y":0}}"#,
            br#"{"header":{"frame_id":"world"},"point":{"x":2e15,"y":0}}"#,
            br#"{"point":{"x":0,"y":0}}"#,
            b"[]",
        ] {
            assert!(parse(bad).is_err());
        }
    }
}
