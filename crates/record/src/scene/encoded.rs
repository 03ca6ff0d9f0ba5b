//! A batched drawing encoded as it is drawn: the bytes of [`snapshot`]'s `SceneUpdate`
//! without building it.
//!
//! Building 10,000 bodies' primitives as messages, then encoding them, was most of what a
//! big scene's drawing cost: every primitive a struct in a list allocated for the drawing,
//! and prost's encoding of the nested messages measuring each one again at every level
//! above it. Here each primitive is encoded by prost as it is drawn (a message on the
//! stack), into its entity's list of that kind; an entity's lists are then joined in the
//! order of their field numbers, behind its header (the fields before them, encoded by
//! prost). The bytes are prost's encoding of [`snapshot`]'s message, byte for byte: the
//! tests compare the two.

use prost::Message;
use prost::encoding::{WireType, encode_key, encode_varint, encoded_len_varint, fixed32, key_len};
use ricochet_geom::Vec2;
use ricochet_log::messages::fox::{
    Color, CubePrimitive, CylinderPrimitive, LinePrimitive, SceneEntity, Timestamp,
};
use ricochet_sim::{BodyKind, Layers, World};

use super::{
    Canvas, Style, delete_all, draw_body, fan_indices, for_each_batch, line_list, p3, planar,
    snapshot, wire,
};

// Field numbers of `foxglove.SceneUpdate`, `foxglove.SceneEntity` and
// `foxglove.TriangleListPrimitive` (foxglove's schemas).
const UPDATE_DELETIONS: u32 = 1;
const UPDATE_ENTITIES: u32 = 2;
const ENTITY_CUBES: u8 = 8;
const ENTITY_CYLINDERS: u8 = 10;
const ENTITY_LINES: u32 = 11;
const ENTITY_TRIANGLES: u32 = 12;
const TRIANGLES_POSE: u32 = 1;
const TRIANGLES_POINTS: u8 = 2;
const TRIANGLES_COLOR: u32 = 3;
const TRIANGLES_INDICES: u32 = 5;

/// About what a body's drawing takes, encoded (10,000 asteroids, half circles and half
/// polygons, average 152 bytes): the room a drawing reserves for each.
const BODY_BYTES: usize = 160;

/// The encoding of [`snapshot`]`(w, layers, statics, style, ts)`: the same bytes as
/// `snapshot(..).encode_to_vec()`. A batched drawing is encoded as it is drawn; a drawing
/// body by body (at most 256 bodies) is built, then encoded.
pub fn snapshot_encoded(
    w: &World,
    layers: &Layers,
    statics: bool,
    style: Style,
    ts: Timestamp,
) -> Vec<u8> {
    if style == Style::PerBody {
        return snapshot(w, layers, statics, style, ts).encode_to_vec();
    }
    // Room for the whole drawing at once: 10,000 asteroids' 1.5 MB were otherwise copied
    // each time the buffer grew.
    let drawn = w.movers().len();
    let drawn = if statics { w.len() - drawn } else { drawn };
    let mut out = Vec::with_capacity(drawn * BODY_BYTES);
    prost::encoding::message::encode(UPDATE_DELETIONS, &delete_all(ts), &mut out);
    let chosen = (0..w.len()).filter(|&i| (w.kind[i] == BodyKind::Static) == statics);
    let mut lists = Lists::default();
    for_each_batch(w, layers, chosen, |batch| {
        if batch.room.points > 0 {
            lists.triangles = Some(batch.color(w));
        }
        for &i in batch.bodies {
            draw_body(&mut lists, w, i);
        }
        lists.finish(&batch.entity(w, ts), &mut out);
    });
    out
}

/// One entity's primitives, encoded: each list as the entity's repeated field holds it
/// (the triangle list's points and indices apart, for its one message).
#[derive(Default)]
struct Lists {
    cubes: Vec<u8>,
    cylinders: Vec<u8>,
    line: Option<LinePrimitive>,
    /// The triangle list's colour, once it has one.
    triangles: Option<Color>,
    /// The triangle list's points, each a `points` field.
    points: Vec<u8>,
    /// How many points `points` holds.
    count: u32,
    indices: Vec<u32>,
}

impl Canvas for Lists {
    fn cube(&mut self, cube: CubePrimitive) {
        wire::cube(&mut self.cubes, ENTITY_CUBES, &cube);
    }

    fn cylinder(&mut self, cylinder: CylinderPrimitive) {
        wire::cylinder(&mut self.cylinders, ENTITY_CYLINDERS, &cylinder);
    }

    fn fan(&mut self, outline: impl Iterator<Item = Vec2>, color: Color) {
        debug_assert!(
            self.triangles.is_none_or(|c| c == color),
            "one colour a batch"
        );
        self.triangles.get_or_insert(color);
        let first = self.count;
        for v in outline {
            wire::point3(&mut self.points, TRIANGLES_POINTS, &p3(v));
            self.count += 1;
        }
        self.indices.extend(fan_indices(first, self.count - first));
    }

    fn segment(&mut self, a: Vec2, b: Vec2, color: Color) {
        let line = self.line.get_or_insert_with(|| line_list(color));
        line.points.extend([a, b].map(p3));
    }
}

impl Lists {
    /// Appends the entity `header` (no primitive yet) with these primitives to `out`, as a
    /// `SceneUpdate`'s `entities` field, and empties the lists for the next entity.
    fn finish(&mut self, header: &SceneEntity, out: &mut Vec<u8>) {
        let pose = planar(Vec2::ZERO, 0.0);
        let triangles = self.triangles.map(|color| {
            let len = pose.as_ref().map_or(0, |p| {
                prost::encoding::message::encoded_len(TRIANGLES_POSE, p)
            }) + self.points.len()
                + prost::encoding::message::encoded_len(TRIANGLES_COLOR, &color)
                + fixed32::encoded_len_packed(TRIANGLES_INDICES, &self.indices);
            (color, len)
        });
        let line = self.line.as_ref().map_or(0, |l| {
            prost::encoding::message::encoded_len(ENTITY_LINES, l)
        });
        let len = header.encoded_len()
            + self.cubes.len()
            + self.cylinders.len()
            + line
            + triangles.map_or(0, |(_, len)| {
                key_len(ENTITY_TRIANGLES) + encoded_len_varint(len as u64) + len
            });
        out.reserve(key_len(UPDATE_ENTITIES) + encoded_len_varint(len as u64) + len);
        encode_key(UPDATE_ENTITIES, WireType::LengthDelimited, out);
        encode_varint(len as u64, out);
        header.encode_raw(out);
        out.extend_from_slice(&self.cubes);
        out.extend_from_slice(&self.cylinders);
        if let Some(l) = &self.line {
            prost::encoding::message::encode(ENTITY_LINES, l, out);
        }
        if let Some((color, len)) = triangles {
            encode_key(ENTITY_TRIANGLES, WireType::LengthDelimited, out);
            encode_varint(len as u64, out);
            if let Some(p) = &pose {
                prost::encoding::message::encode(TRIANGLES_POSE, p, out);
            }
            out.extend_from_slice(&self.points);
            prost::encoding::message::encode(TRIANGLES_COLOR, &color, out);
            fixed32::encode_packed(TRIANGLES_INDICES, &self.indices, out);
        }
        self.cubes.clear();
        self.cylinders.clear();
        self.line = None;
        self.triangles = None;
        self.points.clear();
        self.count = 0;
        self.indices.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{CHUNK_PARTS, PER_BODY_LIMIT};
    use ricochet_geom::Shape;
    use ricochet_sim::{BodyDef, Simulation, load_scenario};

    /// Every shape kind of `scenarios/shapes.toml` (compounds too), `copies` times over,
    /// half of them static, two copies of three on the first layer (so that it takes several
    /// entities), one copy at the origin unturned (zeros the encoding leaves out) and one
    /// at minus zero, and a static terrain chain.
    fn every_kind(copies: usize) -> Simulation {
        let text = include_str!("../../../../scenarios/shapes.toml");
        let mut scenario = load_scenario(text, "shapes.toml").expect("the shipped scenario");
        let base = std::mem::take(&mut scenario.bodies);
        for k in 0..copies {
            for (j, b) in base.iter().enumerate() {
                let mut b = b.clone();
                b.name = format!("{}-{k}", b.name);
                match k {
                    0 => (b.position, b.angle) = (Vec2::ZERO, 0.0),
                    1 => (b.position, b.angle) = (Vec2::new(-0.0, -0.0), -0.0),
                    _ => b.position += Vec2::new(k as f64 * 0.37, j as f64 * -1.3),
                }
                if (k + j) % 2 == 0 {
                    b.kind = BodyKind::Static;
                }
                if k % 3 != 0 {
                    b.layer = base[0].layer;
                }
                scenario.bodies.push(b);
            }
        }
        let points = [
            Vec2::new(-5.0, 0.0),
            Vec2::new(0.0, 1.0),
            Vec2::new(5.0, 0.5),
        ];
        scenario.bodies.push(BodyDef {
            name: "hills".to_owned(),
            kind: BodyKind::Static,
            shape: Shape::chain(&points, None, None).expect("a valid chain"),
            ..base[0].clone()
        });
        Simulation::new(&scenario)
    }

    #[test]
    fn the_encoding_is_prosts_encoding_of_the_drawing() {
        let sim = every_kind(200);
        let (w, layers) = (sim.world(), &sim.scenario().world.layers);
        assert!(w.len() > PER_BODY_LIMIT);
        let ts = Timestamp::new(3, 250_000_000);
        for statics in [false, true] {
            for style in [Style::Batched, Style::PerBody] {
                let drawing = snapshot(w, layers, statics, style, ts);
                assert_eq!(
                    snapshot_encoded(w, layers, statics, style, ts),
                    drawing.encode_to_vec(),
                    "statics {statics}, {style:?}"
                );
            }
        }
        // What the comparison covered: every list of an entity, and a layer over several.
        let all: Vec<_> = [false, true]
            .into_iter()
            .flat_map(|statics| snapshot(w, layers, statics, Style::Batched, ts).entities)
            .collect();
        assert!(all.iter().any(|e| !e.cubes.is_empty()));
        assert!(all.iter().any(|e| !e.cylinders.is_empty()));
        assert!(all.iter().any(|e| !e.triangles.is_empty()));
        assert!(all.iter().any(|e| !e.lines.is_empty()));
        assert!(
            all.iter().any(|e| e.id.ends_with("/1")),
            "a layer past {CHUNK_PARTS} parts"
        );
    }

    #[test]
    fn an_empty_drawing_is_prosts_encoding_too() {
        let sim = every_kind(0);
        let (w, layers) = (sim.world(), &sim.scenario().world.layers);
        let ts = Timestamp::new(0, 0);
        let moving = snapshot(w, layers, false, Style::Batched, ts);
        assert!(moving.entities.is_empty(), "only the static chain");
        assert_eq!(
            snapshot_encoded(w, layers, false, Style::Batched, ts),
            moving.encode_to_vec()
        );
    }
}
