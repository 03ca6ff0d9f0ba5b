"""Reads Ricochet logs with the official readers and checks every message of every channel.

Usage: python tests/python/check_mcap.py [--draw-every-frame] LOG.mcap [LOG.mcap ...]

(`--draw-every-frame`: the logs were recorded with `ricochet run --draw-every-frame`, so every
frame may draw, whatever the scene's size.)

Each log is read with the official Python `mcap` reader, every CRC checked (the data
section's, each chunk's, the summary's), and every message is decoded with
`mcap-protobuf-support` from the schema the log embeds. Then:

- Channels: exactly the topics `ricochet run` writes, each with its protobuf schema
  (`/validation` optional), and the summary's message counts match what was read.
- No message has a field its schema does not declare, and each one re-encodes to exactly
  its bytes (canonical protobuf, what a deterministic log must be).
- `/scene`, `/scene/static`, `/scene/contacts`, `/tf` and `/events` against the OFFICIAL Foxglove schemas
  (the `foxglove-schemas-protobuf` package): the descriptor the log embeds declares the
  same message as the official one (field names, numbers, types, labels, nested types,
  enums), and every message parses with the official class, with no unknown field, into
  the same message field for field (`MessageToDict`) as the decoder's.
- Times: `log_time == publish_time`, nondecreasing through the file, each a whole frame
  (`frame * dt_ns`); `/bodies`, `/contacts` and `/stats` hold one message per frame, the
  frames consecutive from 0, at `frame * dt_ns` (and `/validation`, when recorded);
  `/bodies.dt` is the same every frame, `dt_ns` is it rounded to whole nanoseconds,
  `/bodies.time` is `frame * dt`, and the timestamps inside messages agree.
- `/bodies`: every body's full state is rebuilt frame by frame exactly as `BodyStates`
  (crates/log/src/bodies.rs) does: a keyframe replaces every moving body (static ones are
  kept); between keyframes a body
  not listed, or listed without `position` / `angle`, moves as `previous + velocity * dt`
  and `previous + angular_velocity * dt` with this frame's velocities (f64, multiply then
  add), unless `still`; unlisted velocities are unchanged, or, while the body is `falling`
  (switched by a listed `falling: true` or `false`; a body starts not falling),
  `previous + gravity * dt` (`/bodies.gravity`, per component). A body that appears, and every
  body of a keyframe, has every field; a removed body has every field (its angular
  velocity too) and, if it was alive, its name, layer, shape and kind; a delta neither
  changes what only full listings carry nor sets `still` with a position or an angle.
  Bodies are unique by `(id, generation)` (one per id at a time, a reused id has a later
  generation, a removed body never returns), no body vanishes without being listed in
  `removed`, and `/stats.bodies` counts the live bodies.
- `/scene` (moving bodies) and `/scene/static` (static ones), as Foxglove shows them after a
  seek (the last message of each TOPIC at or before the time: so each message is whole):
  every message is a delete-all stamped at its time, then the entities of its topic, each
  in `world`, not `frame_locked`, stamped then, with no lifetime, only cubes, cylinders,
  one triangle list and one line list (a terrain chain's segments), every number an f32. Both are sent at frame 0. With at most 256
  bodies at frame 0, each live body is one entity `body/ID:GENERATION` on the topic of its
  kind, with metadata `name`, `id`, `layer`, `kind` (`static`, or `dynamic`/`kinematic`)
  and, moving, `velocity` and `angular_velocity` equal to `/bodies`' to the bit; with more,
  each topic's entities are `LAYER/0`, `LAYER/1`, ..., a layer's together and in order,
  holding in order exactly that layer's live bodies in id order, as many as fit in 1024
  body parts (never more, and the next would not fit), with metadata `layer`, `bodies`,
  `first` and `last`. In both, every primitive is where the body's shape is at its
  `/bodies` pose, within f32 rounding (4 f32 epsilons of max(1, |value|)): a circle a
  cylinder at its centre, an AABB an upright cube, an OBB a cube turned by the body's angle
  plus its own, a capsule a cube along its segment and a cylinder at each end, polygons
  fans in the one triangle list in world coordinates. A frame that may draw (below) without
  a message of a topic has exactly the bodies of the topic's last message, none moved or
  turned (to the bit; per body, none with another velocity): what a seek shows then is that
  frame.
- The drawing's pace (README, "Drawing a big scene"): with at most 256 bodies at frame 0
  every frame may draw; with more, frame 0 draws, and a frame that drew `n` bytes of
  `/scene`, `/scene/static`, `/tf` and `/scene/contacts` (as the file holds them) lets the
  next draw no sooner than `ceil(n / 12288)` frames later: a frame before that sends none of
  the four, and what a seek shows there is the last drawing.
- `/tf`: one transform a message, the camera's frame `view` in `world`, upright, at f32
  precision, stamped at its time; sent at frame 0, then only when it moves.
- `/scene/contacts`: one entity `contacts` in `world`, with one `LINE_LIST` of 2 points per
  contact of that frame's `/contacts` (its point, and the point plus the normal times
  max(depth, 0.8)), sent in every frame with contacts and in the frame after the last
  (empty), in no other.
- `/contacts` and `/stats` agree on the number of contacts.

Prints one line per log, then `check_mcap: N passed, N failed`; exits 1 on any problem,
naming it.
"""

import importlib
import math
import struct
import sys
import zlib
from collections import Counter

from google.protobuf import descriptor_pb2, descriptor_pool
from google.protobuf.json_format import MessageToDict
from mcap.reader import make_reader
from mcap.records import Footer
from mcap.stream_reader import MAGIC_SIZE, StreamReader
from mcap_protobuf.decoder import DecoderFactory

EXPECTED = {
    "/scene": "foxglove.SceneUpdate",
    "/tf": "foxglove.FrameTransforms",
    "/scene/contacts": "foxglove.SceneUpdate",
    "/scene/static": "foxglove.SceneUpdate",
    "/bodies": "ricochet.Bodies",
    "/contacts": "ricochet.Contacts",
    "/stats": "ricochet.Stats",
    "/events": "foxglove.Log",
}
OPTIONAL = {"/validation": "ricochet.Validation", "/input": "ricochet.Input"}
PER_FRAME = ("/bodies", "/contacts", "/stats")
WORLD = "world"
# The recorder's scene styles: an entity per body up to this many bodies at frame 0, above
# that per-layer batches of at most CHUNK_PARTS body parts.
PER_BODY_LIMIT = 256
CHUNK_PARTS = 1024
# A batched scene's drawing of n bytes waits ceil(n / DRAW_BYTES_PER_FRAME) frames.
DRAW_BYTES_PER_FRAME = 12 * 1024
SCENE_TOPICS = ("/scene", "/scene/static", "/tf", "/scene/contacts")
# Drawings are at f32 precision: within a few f32 roundings of max(1, |value|).
F32_TOLERANCE = 4 * 2.0**-23


class Problem(Exception):
    pass


def official_class(schema_name):
    """The class of the official Foxglove message `foxglove.X`, from foxglove-schemas-protobuf."""
    package, name = schema_name.split(".")
    assert package == "foxglove"
    module = importlib.import_module(f"foxglove_schemas_protobuf.{name}_pb2")
    return getattr(module, name)


def embedded_descriptor(schema):
    """The message descriptor a channel's schema (a FileDescriptorSet) declares."""
    fds = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
    pool = descriptor_pool.DescriptorPool()
    files = {f.name: f for f in fds.file}

    def add(f):
        for dep in f.dependency:
            if dep in files:
                add(files.pop(dep))
        pool.Add(f)

    while files:
        add(files.popitem()[1])
    return pool.FindMessageTypeByName(schema.name)


def field_signature(f):
    return (
        f.number,
        f.type,
        f.label,
        f.has_presence,
        f.containing_oneof.name if f.containing_oneof else None,
        f.message_type.full_name if f.message_type else None,
        f.enum_type.full_name if f.enum_type else None,
    )


def compare_descriptors(ours, theirs, seen=None):
    """Raises Problem where two message descriptors declare different messages."""
    seen = set() if seen is None else seen
    if ours.full_name != theirs.full_name:
        raise Problem(f"embedded {ours.full_name} where the official schema has {theirs.full_name}")
    if ours.full_name in seen:
        return
    seen.add(ours.full_name)
    a = {f.name: field_signature(f) for f in ours.fields}
    b = {f.name: field_signature(f) for f in theirs.fields}
    if a != b:
        diff = sorted(set(a.items()) ^ set(b.items()))
        raise Problem(f"embedded {ours.full_name} differs from the official one: {diff}")
    for f in ours.fields:
        g = theirs.fields_by_name[f.name]
        if f.message_type:
            compare_descriptors(f.message_type, g.message_type, seen)
        if f.enum_type:
            va = {v.name: v.number for v in f.enum_type.values}
            vb = {v.name: v.number for v in g.enum_type.values}
            if va != vb:
                raise Problem(f"embedded enum {f.enum_type.full_name} {va} differs from the official {vb}")


def check_unknown_and_canonical(msg, raw, what):
    """No field outside the schema, anywhere in the message, and `raw` is its canonical encoding."""
    bare = type(msg)()
    bare.CopyFrom(msg)
    bare.DiscardUnknownFields()
    if bare.ByteSize() != msg.ByteSize():
        raise Problem(f"{what}: fields its schema does not declare ({msg.ByteSize() - bare.ByteSize()} bytes)")
    if bare.SerializeToString(deterministic=True) != raw:
        raise Problem(f"{what}: the bytes are not the message's canonical encoding")


def check_crcs(f):
    """Every CRC of the file: the data section's and each chunk's (a pass of the official
    stream reader; the indexed reader only checks the chunks it reads), and the summary's."""
    f.seek(0)
    footer = None
    for record in StreamReader(f, validate_crcs=True).records:
        if isinstance(record, Footer):
            footer = record
    if footer is None or footer.summary_start == 0:
        raise Problem("no summary: the log is not indexed")
    end = f.seek(0, 2) - MAGIC_SIZE - 4  # the footer's summary_crc covers all before it
    f.seek(footer.summary_start)
    crc = zlib.crc32(f.read(end - footer.summary_start))
    if crc != footer.summary_crc:
        raise Problem(f"summary CRC {crc:#x}, the footer says {footer.summary_crc:#x}")
    f.seek(0)


def bits(*xs):
    return struct.pack(f"<{len(xs)}d", *xs)


def ts_ns(t):
    return t.seconds * 1_000_000_000 + t.nanos


def f32(x):
    """`x` rounded to the nearest f32 (None if it has none: beyond the f32 range)."""
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:
        return None


DEPTH = f32(0.05)


def is_f32(x):
    return f32(x) == x


def close(got, want):
    return abs(got - want) <= F32_TOLERANCE * max(1.0, abs(got), abs(want))


def close_angle(got, want):
    return abs(math.remainder(got - want, math.tau)) <= F32_TOLERANCE * max(1.0, abs(want))


def shape_parts(shape):
    """The primitives of a `ricochet.Shape`, in order."""
    if shape.WhichOneof("kind") == "compound":
        return [q for p in shape.compound.parts for q in shape_parts(p)]
    return [shape]


def number_text(x):
    """A number as `ricochet_geom::Number` writes it, read back (None if it is not one)."""
    try:
        return float(x)
    except ValueError:
        return None


def numbers_text(s):
    """`[x, y]` as `ricochet_geom::Numbers` writes it, read back."""
    if not (s.startswith("[") and s.endswith("]")) or s.count(", ") != 1:
        return None
    xs = [number_text(v) for v in s[1:-1].split(", ")]
    return None if None in xs else xs


def planar(pose, what):
    """(x, y, yaw) of a `foxglove.Pose`; a Problem unless it is in the plane (z = 0, a unit
    quaternion about z) at f32 precision."""
    p, q = pose.position, pose.orientation
    numbers = (p.x, p.y, p.z, q.x, q.y, q.z, q.w)
    if p.z != 0.0 or q.x != 0.0 or q.y != 0.0 or not close(q.z * q.z + q.w * q.w, 1.0):
        raise Problem(f"{what}: pose ({p.x}, {p.y}, {p.z}) turned ({q.x}, {q.y}, {q.z}, {q.w}): not in the plane")
    if not all(is_f32(x) for x in numbers):
        raise Problem(f"{what}: pose {numbers} not at f32 precision")
    return p.x, p.y, 2.0 * math.atan2(q.z, q.w)


def drawing(bodies):
    """What the bodies (`[((id, generation), state)]`, in order) make in one entity: the
    cubes and the cylinders, each `(x, y, yaw or None for any, width, height, whose)`, and
    the triangle list's points, its indices and whose polygon starts at each point."""
    cubes, cylinders, points, indices, owners = [], [], [], [], []
    lines = []  # a terrain chain's segments, as the ends of a line list, in world coordinates
    for (i, g), b in bodies:
        (x, y), a = b["position"], b["angle"]
        s, c = math.sin(a), math.cos(a)

        def at(px, py):
            return x + (c * px - s * py), y + (s * px + c * py)

        for n, p in enumerate(shape_parts(b["shape"])):
            whose = f"body {i}:{g} part {n}"
            kind = p.WhichOneof("kind")
            if kind == "circle":
                r = p.circle.radius
                cylinders.append((*at(*p.circle.center), 0.0, 2 * r, 2 * r, whose))
            elif kind in ("aabb", "obb"):
                box = getattr(p, kind)
                turn = 0.0 if kind == "aabb" else a + box.angle
                w, h = 2 * box.half_extents[0], 2 * box.half_extents[1]
                cubes.append((*at(*box.center), turn, w, h, whose))
            elif kind == "capsule" and p.capsule.radius == 0:
                # A loaded capsule's radius is above 0: radius 0 is a chain's segment
                # (/bodies logs a chain as a compound of them), drawn as a line.
                lines += [(at(*p.capsule.a), whose), (at(*p.capsule.b), whose)]
            elif kind == "capsule":
                (ax, ay), (bx, by), r = at(*p.capsule.a), at(*p.capsule.b), p.capsule.radius
                length = math.hypot(bx - ax, by - ay)
                turn = math.atan2(by - ay, bx - ax) if length > 0 else None
                cubes.append(((ax + bx) / 2, (ay + by) / 2, turn, length, 2 * r, f"{whose} (capsule's segment)"))
                cylinders.append((ax, ay, 0.0, 2 * r, 2 * r, f"{whose} (capsule end a)"))
                cylinders.append((bx, by, 0.0, 2 * r, 2 * r, f"{whose} (capsule end b)"))
            elif kind == "polygon":
                v = p.polygon.vertices
                first, count = len(points), len(v) // 2
                owners.append((first, whose))
                points += [at(v[2 * k], v[2 * k + 1]) for k in range(count)]
                indices += [j for k in range(1, count - 1) for j in (first, first + k, first + k + 1)]
            else:
                raise Problem(f"{whose}: a shape of kind {kind}")
    return cubes, cylinders, points, indices, owners, lines


def compare_lines(e, lines, what):
    """Raises Problem unless `e` draws the chain segments `lines` as its one line list."""
    if len(e.lines) != (1 if lines else 0):
        raise Problem(f"{what}: {len(e.lines)} line lists, its bodies have {len(lines) // 2} chain segments")
    if not lines:
        return
    ll = e.lines[0]
    if ll.type != 2 or planar(ll.pose, f"{what}: the line list") != (0.0, 0.0, 0.0) or not ll.thickness > 0:
        raise Problem(f"{what}: the chain's lines are not a line list in world coordinates (type {ll.type}, thickness {ll.thickness})")
    if len(ll.points) != len(lines):
        raise Problem(f"{what}: a line list of {len(ll.points)} points, its chains' segments have {len(lines)} ends")
    for k, (p, ((x, y), whose)) in enumerate(zip(ll.points, lines)):
        if not (is_f32(p.x) and is_f32(p.y) and p.z == 0.0 and close(p.x, x) and close(p.y, y)):
            raise Problem(f"{what}: {whose} end {k % 2} drawn at ({p.x!r}, {p.y!r}, {p.z!r}), its shape at ({x!r}, {y!r})")


def compare_drawing(e, bodies, what):
    """Raises Problem unless entity `e` draws `bodies` (in order) where their shapes are."""
    cubes, cylinders, points, indices, owners, lines = drawing(bodies)
    compare_lines(e, lines, what)
    for name, got, want in (("cubes", e.cubes, cubes), ("cylinders", e.cylinders, cylinders)):
        if len(got) != len(want):
            raise Problem(f"{what}: {len(got)} {name}, its bodies' shapes make {len(want)}")
        for k, (prim, (x, y, turn, w, h, whose)) in enumerate(zip(got, want)):
            px, py, yaw = planar(prim.pose, f"{what}: {name}[{k}] ({whose})")
            size = prim.size
            if not all(is_f32(v) for v in (size.x, size.y, size.z)):
                raise Problem(f"{what}: {name}[{k}] ({whose}): size not at f32 precision")
            if not (close(px, x) and close(py, y) and (turn is None or close_angle(yaw, turn))
                    and close(size.x, w) and close(size.y, h) and size.z == DEPTH):
                raise Problem(f"{what}: {name}[{k}] ({whose}) drawn at ({px!r}, {py!r}) turned {yaw!r}, of size ({size.x!r}, {size.y!r}, {size.z!r}); "
                              f"its shape at ({x!r}, {y!r}) turned {turn!r}, of size ({w!r}, {h!r})")
    if len(e.triangles) != (1 if points else 0):
        raise Problem(f"{what}: {len(e.triangles)} triangle lists, its bodies have {len(owners)} polygons")
    if not points:
        return
    tl = e.triangles[0]
    if planar(tl.pose, f"{what}: the triangle list") != (0.0, 0.0, 0.0):
        raise Problem(f"{what}: the triangle list is not in world coordinates")
    if len(tl.points) != len(points) or list(tl.indices) != indices or tl.colors:
        raise Problem(f"{what}: a triangle list of {len(tl.points)} points, indices {list(tl.indices)[:12]}...; "
                      f"its polygons {len(points)} points, as fans {indices[:12]}...")
    for k, (p, (x, y)) in enumerate(zip(tl.points, points)):
        if not (is_f32(p.x) and is_f32(p.y) and p.z == 0.0 and close(p.x, x) and close(p.y, y)):
            first, whose = max(o for o in owners if o[0] <= k)
            raise Problem(f"{what}: {whose} vertex {k - first} drawn at ({p.x!r}, {p.y!r}, {p.z!r}), its shape at ({x!r}, {y!r})")


def check_color(c, what):
    if not all(is_f32(v) for v in (c.r, c.g, c.b, c.a)):
        raise Problem(f"{what}: colour ({c.r}, {c.g}, {c.b}, {c.a}) not at f32 precision")


class Bodies:
    """Every body's full state, rebuilt from `/bodies` keyframes and deltas as `BodyStates`
    (crates/log/src/bodies.rs) does."""

    # Carried only when a body is listed in full (it appears, or a keyframe).
    FIXED = ("name", "layer", "shape", "static")
    FULL = FIXED + ("angle", "angular_velocity")

    def __init__(self):
        self.live = {}  # (id, generation) -> {field: value}
        self.retired = set()
        self.generation = {}  # id -> latest generation seen
        self.dt = None

    def apply(self, m, frame):
        """Applies frame `frame`'s message."""
        if m.frame != frame:
            raise Problem(f"/bodies frame {m.frame} at frame {frame}")
        if frame == 0 and not m.keyframe:
            raise Problem("/bodies: frame 0 is not a keyframe")
        dt = m.dt
        if not (math.isfinite(dt) and dt > 0.0):
            raise Problem(f"/bodies frame {frame}: dt {dt!r}")
        if self.dt is None:
            self.dt = dt
        elif dt != self.dt:
            raise Problem(f"/bodies frame {frame}: dt {dt!r}, frame 0 had {self.dt!r}")
        if m.time != frame * dt:
            raise Problem(f"/bodies frame {frame}: time {m.time!r}, frame * dt is {frame * dt!r}")
        if len(m.gravity) not in (0, 2):
            raise Problem(f"/bodies frame {frame}: gravity {list(m.gravity)}")
        gravity = tuple(m.gravity) if m.gravity else (0.0, 0.0)
        before = self.live
        removed = set()
        for b in m.removed:
            k = (b.id, b.generation)
            if k in removed:
                raise Problem(f"/bodies frame {frame}: body {k} removed twice")
            removed.add(k)
            # Removed with its last state, every field.
            for f in self.FULL:
                if not b.HasField(f):
                    raise Problem(f"/bodies frame {frame}: removed body {k} lacks {f}")
            if len(b.position) != 2 or len(b.velocity) != 2:
                raise Problem(f"/bodies frame {frame}: removed body {k} lacks position or velocity")
            if k in self.retired:
                raise Problem(f"/bodies frame {frame}: body {k} removed again")
            if k in before:
                for f in self.FIXED:
                    if getattr(b, f) != before[k][f]:
                        raise Problem(f"/bodies frame {frame}: removed body {k} has {f} {getattr(b, f)!r}, alive it had {before[k][f]!r}")
        listed = {}
        for b in m.bodies:
            k = (b.id, b.generation)
            if k in listed:
                raise Problem(f"/bodies frame {frame}: body {k} listed twice")
            listed[k] = b
            if k in removed or k in self.retired:
                raise Problem(f"/bodies frame {frame}: body {k} listed after its removal")
            for f in ("position", "velocity"):
                if len(getattr(b, f)) not in (0, 2):
                    raise Problem(f"/bodies frame {frame}: body {k} {f} {list(getattr(b, f))}")
        if m.keyframe:
            gone = sorted(k for k in set(before) - removed - set(listed) if not before[k]["static"])
            if gone:
                raise Problem(f"/bodies keyframe {frame}: bodies {gone[:5]} vanished without being listed in removed")
        live = {}
        for k, old in before.items():
            if k in removed:
                continue
            b = listed.get(k)
            if m.keyframe and not old["static"]:
                continue  # listed in full below (static bodies are kept)
            state = dict(old)
            if b is not None:
                for f in self.FIXED:
                    if b.HasField(f) and getattr(b, f) != old[f]:
                        raise Problem(f"/bodies frame {frame}: a delta of body {k} changes {f} (to {getattr(b, f)!r}), which readers take only from full listings")
                if b.still and (b.position or b.HasField("angle")):
                    raise Problem(f"/bodies frame {frame}: body {k} is still but lists a position or an angle")
                if b.HasField("falling"):
                    state["falling"] = b.falling
                if b.velocity:
                    state["velocity"] = tuple(b.velocity)
                elif state.get("falling"):
                    (vx, vy), (gx, gy) = state["velocity"], gravity
                    state["velocity"] = (vx + gx * dt, vy + gy * dt)
                if b.HasField("angular_velocity"):
                    state["angular_velocity"] = b.angular_velocity
                if b.still:
                    live[k] = state
                    continue
            elif state.get("falling"):
                (vx, vy), (gx, gy) = state["velocity"], gravity
                state["velocity"] = (vx + gx * dt, vy + gy * dt)
            # What the integrator predicts, with this frame's velocities: f64, multiply then add.
            if b is not None and b.position:
                state["position"] = tuple(b.position)
            else:
                (x, y), (vx, vy) = old["position"], state["velocity"]
                state["position"] = (x + vx * dt, y + vy * dt)
            if b is not None and b.HasField("angle"):
                state["angle"] = b.angle
            else:
                state["angle"] = old["angle"] + state["angular_velocity"] * dt
            live[k] = state
        for k, b in listed.items():
            if k in live:
                continue
            new = k not in before
            missing = [f for f in self.FULL if not b.HasField(f)]
            if len(b.position) != 2 or len(b.velocity) != 2:
                missing.append("position/velocity")
            if missing:
                why = "a new body" if new else "a keyframe body"
                raise Problem(f"/bodies frame {frame}: {why} {k} lacks {', '.join(missing)}")
            if b.still:
                raise Problem(f"/bodies frame {frame}: body {k}, listed in full, is still")
            if new:
                last = self.generation.get(b.id)
                if last is not None and b.generation <= last:
                    raise Problem(f"/bodies frame {frame}: id {b.id} reused with generation {b.generation}, after {last}")
                if (b.id, last) in live:
                    raise Problem(f"/bodies frame {frame}: body {k} appears while {(b.id, last)} is alive")
            elif m.keyframe:
                for f in self.FIXED:
                    if getattr(b, f) != before[k][f]:
                        raise Problem(f"/bodies keyframe {frame}: body {k} has {f} {getattr(b, f)!r}, the frame before {before[k][f]!r}")
            state = {f: getattr(b, f) for f in self.FULL}
            state["position"] = tuple(b.position)
            state["velocity"] = tuple(b.velocity)
            state["falling"] = b.HasField("falling") and b.falling
            live[k] = state
            self.generation[b.id] = max(self.generation.get(b.id, b.generation), b.generation)
        for k in removed:
            self.retired.add(k)
            self.generation[k[0]] = max(self.generation.get(k[0], k[1]), k[1])
        self.live = live


def round_ns(seconds):
    """Rust's `(seconds * 1e9).round() as u64`: half away from zero."""
    v = seconds * 1e9
    r = math.floor(v)
    return int(r) + (1 if v - r >= 0.5 else 0)


class Log:
    def __init__(self, path, every_frame=False):
        self.path = path
        self.every_frame = every_frame  # recorded with --draw-every-frame
        self.counts = Counter()
        self.dt_ns = None
        self.frames = 0
        self.bodies = Bodies()
        self.batched = None  # the scene style, chosen at frame 0
        # topic -> the bodies its last message drew: (id, generation) -> the bits of their
        # pose (and velocities), and the frame it was sent at
        self.drawn = {}
        self.views = 0  # /tf messages
        self.view = None  # the last one's (x, y)
        self.contacts_shown = False  # the last /scene/contacts drew some
        self.next_drawing = 0  # the first frame that may draw again (a batched scene)
        self.drawn_bytes = 0  # this frame's scene-topic bytes
        self.validation = False
        self.validation_mismatches = 0

    def check(self):
        with open(self.path, "rb") as f:
            check_crcs(f)
            reader = make_reader(f, validate_crcs=True, decoder_factories=[DecoderFactory()])
            summary = reader.get_summary()
            if summary is None or summary.statistics is None:
                raise Problem("no summary or statistics: the log is not indexed")
            topics = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
            expected = dict(EXPECTED)
            expected.update({t: n for t, n in OPTIONAL.items() if t in topics})
            if topics != expected:
                raise Problem(f"channels {topics}, expected {expected}")
            self.validation = "/validation" in topics
            for c in summary.channels.values():
                s = summary.schemas[c.schema_id]
                if c.message_encoding != "protobuf" or s.encoding != "protobuf":
                    raise Problem(f"{c.topic}: message encoding {c.message_encoding!r}, schema encoding {s.encoding!r}, expected protobuf")
                if s.name.startswith("foxglove."):
                    try:
                        compare_descriptors(embedded_descriptor(s), official_class(s.name).DESCRIPTOR)
                    except Problem as e:
                        raise Problem(f"{c.topic}: {e}") from None
            official = {}
            group, group_time = {}, 0
            for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=False):
                topic = channel.topic
                where = f"{topic} at {message.log_time} ns"
                if message.log_time != message.publish_time:
                    raise Problem(f"{where}: publish_time {message.publish_time} != log_time")
                if message.log_time < group_time:
                    raise Problem(f"{where}: log_time goes back (after {group_time} ns)")
                check_unknown_and_canonical(decoded, message.data, where)
                if schema.name.startswith("foxglove."):
                    cls = official.setdefault(schema.name, official_class(schema.name))
                    theirs = cls.FromString(message.data)
                    check_unknown_and_canonical(theirs, message.data, f"{where} (official {schema.name})")
                    a = MessageToDict(decoded, preserving_proto_field_name=True)
                    b = MessageToDict(theirs, preserving_proto_field_name=True)
                    if a != b:
                        raise Problem(f"{where}: the official {schema.name} reads {b}, the embedded schema {a}")
                self.counts[topic] += 1
                if message.log_time != group_time:
                    self.frame(group_time, group)
                    group, group_time = {}, message.log_time
                    self.drawn_bytes = 0
                group.setdefault(topic, []).append(decoded)
                if topic in SCENE_TOPICS:
                    self.drawn_bytes += len(message.data)
            if not group:
                raise Problem("no message")
            self.frame(group_time, group)
            stats = summary.statistics
            if sum(self.counts.values()) != stats.message_count:
                raise Problem(f"read {sum(self.counts.values())} messages, the summary says {stats.message_count}")
            for c in summary.channels.values():
                if stats.channel_message_counts.get(c.id, 0) != self.counts[c.topic]:
                    raise Problem(f"{c.topic}: read {self.counts[c.topic]} messages, the summary says {stats.channel_message_counts.get(c.id, 0)}")
        total = sum(self.counts.values())
        per_topic = ", ".join(f"{t} {self.counts[t]}" for t in list(EXPECTED) + list(OPTIONAL) if t in EXPECTED or t in self.counts)
        extra = f" ({self.validation_mismatches} mismatches)" if self.validation else ""
        return (f"ok, CRCs checked, {self.frames} frames of {self.dt_ns or 0} ns, {len(self.bodies.live)} bodies at the end, "
                f"{total} messages: {per_topic}{extra}; "
                f"scene {'batched' if self.batched else 'per body'}, /tf {self.views} views")

    def frame(self, t, msgs):
        """Checks the messages logged at time `t`: one frame's."""
        frame = self.frames
        for topic in PER_FRAME + (("/validation",) if self.validation else ()):
            got = msgs.get(topic, [])
            if len(got) != 1:
                raise Problem(f"{topic}: {len(got)} messages at {t} ns (frame {frame} due), expected one per frame")
            if got[0].frame != frame:
                raise Problem(f"{topic}: frame {got[0].frame} at {t} ns, where frame {frame} was due")
        if frame == 1:
            self.dt_ns = t
        dt = self.dt_ns or 0
        if t != frame * dt or (frame > 0 and dt == 0):
            raise Problem(f"frame {frame} at {t} ns, expected frame * dt_ns = {frame} * {dt} ns")
        self.frames += 1
        if "/validation" in msgs:
            self.validation_mismatches += msgs["/validation"][0].mismatches
        self.bodies.apply(msgs["/bodies"][0], frame)
        if frame == 1 and round_ns(self.bodies.dt) != dt:
            raise Problem(f"frames {dt} ns apart, /bodies.dt {self.bodies.dt!r} s rounds to {round_ns(self.bodies.dt)} ns")
        live = self.bodies.live
        stats = msgs["/stats"][0]
        if stats.bodies != len(live):
            raise Problem(f"/stats frame {frame}: {stats.bodies} bodies, /bodies rebuilds {len(live)}")
        contacts = len(msgs["/contacts"][0].contacts)
        if stats.contacts != contacts:
            raise Problem(f"/stats frame {frame}: {stats.contacts} contacts, /contacts lists {contacts}")
        if frame == 0:
            self.batched = len(live) > PER_BODY_LIMIT
        if self.batched and not self.every_frame and frame < self.next_drawing:
            early = [t for t in SCENE_TOPICS if t in msgs]
            if early:
                raise Problem(f"frame {frame}: {early} drawn before the pace allows (frame {self.next_drawing})")
            return self.check_events(frame, t, msgs)
        if self.batched and self.drawn_bytes:
            self.next_drawing = frame + max(1, -(-self.drawn_bytes // DRAW_BYTES_PER_FRAME))
        for topic in ("/scene", "/scene/static"):
            sent = msgs.get(topic, [])
            if len(sent) > 1 or (frame == 0 and not sent):
                raise Problem(f"{topic} frame {frame}: {len(sent)} messages, expected at most one (one at frame 0)")
            ours = sorted((k, b) for k, b in live.items() if b["static"] == (topic == "/scene/static"))
            if sent:
                self.check_scene(topic, frame, t, sent[0], ours)
            self.check_unmoved(topic, frame, ours, sent)
        for m in msgs.get("/tf", []):
            self.check_view(frame, t, m)
        if frame == 0 and self.views == 0:
            raise Problem("/tf frame 0: no view frame")
        self.check_contacts(frame, t, msgs["/contacts"][0].contacts, msgs.get("/scene/contacts", []))
        self.check_events(frame, t, msgs)

    def check_events(self, frame, t, msgs):
        for e in msgs.get("/events", []):
            if ts_ns(e.timestamp) != t:
                raise Problem(f"/events frame {frame}: stamped {ts_ns(e.timestamp)} ns at {t} ns")

    def pose_bits(self, b, velocities):
        """The bits a scene shows of a body: its pose, and its velocities if shown."""
        shown = (*b["position"], b["angle"])
        if velocities:
            shown += (*b["velocity"], b["angular_velocity"])
        return bits(*shown)

    def check_unmoved(self, topic, frame, ours, sent):
        """After a frame's `topic` (sent, or not): what its last message drew is the frame's."""
        velocities = not self.batched and topic == "/scene"
        now = {k: self.pose_bits(b, velocities) for k, b in ours}
        if sent:
            self.drawn[topic] = (frame, now)
            return
        at, drawn = self.drawn[topic]
        if drawn != now:
            went = sorted(set(drawn) - set(now))[:5]
            came = sorted(set(now) - set(drawn))[:5]
            moved = sorted(k for k in set(now) & set(drawn) if now[k] != drawn[k])[:5]
            raise Problem(f"{topic} frame {frame}: not sent, so a seek shows frame {at}'s bodies; since then {went} went, {came} came, {moved} moved, turned or changed velocity")

    def check_scene(self, topic, frame, t, s, ours):
        """One whole `/scene` or `/scene/static` message: exactly the bodies `ours` (in id order)."""
        where = f"{topic} frame {frame}"
        if len(s.deletions) != 1 or s.deletions[0].type != 1 or s.deletions[0].id or ts_ns(s.deletions[0].timestamp) != t:
            raise Problem(f"{where}: not one delete-all at {t} ns, then the scene")
        ids = [e.id for e in s.entities]
        if len(ids) != len(set(ids)):
            raise Problem(f"{where}: an entity twice")
        for e in s.entities:
            what = f"{where}: entity {e.id}"
            if e.frame_id != WORLD or e.frame_locked or ts_ns(e.timestamp) != t or e.HasField("lifetime"):
                raise Problem(f"{what} (frame {e.frame_id}, locked {e.frame_locked}, lifetime {e.HasField('lifetime')}) is not drawn in {WORLD!r} at {t} ns for ever")
            if e.arrows or e.spheres or e.texts or e.models:
                raise Problem(f"{what}: draws more than cubes, cylinders, triangles and lines")
            for prim in (*e.cubes, *e.cylinders, *e.triangles, *e.lines):
                check_color(prim.color, what)
        if self.batched:
            self.check_batches(where, s.entities, ours)
            return
        entities = {e.id: e for e in s.entities}
        want = {f"body/{i}:{g}": ((i, g), b) for (i, g), b in ours}
        if set(entities) != set(want):
            raise Problem(f"{where}: draws {sorted(set(entities) - set(want))[:5]}, not live bodies of this topic; does not draw {sorted(set(want) - set(entities))[:5]}")
        for name, ((i, g), b) in want.items():
            e = entities[name]
            meta = [(kv.key, kv.value) for kv in e.metadata]
            head = [("name", b["name"]), ("id", f"{i}:{g}"), ("layer", b["layer"])]
            keys = ["name", "id", "layer", "kind"] + ([] if b["static"] else ["velocity", "angular_velocity"])
            ok = [k for k, _ in meta] == keys and meta[:3] == head
            if ok:
                kind = meta[3][1]
                ok = kind == "static" if b["static"] else kind in ("dynamic", "kinematic")
            if ok and not b["static"]:
                v, w = numbers_text(meta[4][1]), number_text(meta[5][1])
                ok = v is not None and w is not None and bits(*v, w) == bits(*b["velocity"], b["angular_velocity"])
            if not ok:
                raise Problem(f"{where}: entity {name} has metadata {meta}; /bodies: {head}, static {b['static']}, velocity {b['velocity']}, angular velocity {b['angular_velocity']!r}")
            compare_drawing(e, [((i, g), b)], f"{where}: entity {name}")

    def check_batches(self, where, entities, ours):
        """Batched: each layer's bodies of `ours` in entities `LAYER/0`, `LAYER/1`, ... in order."""
        by_layer = {}
        for k, b in ours:
            by_layer.setdefault(b["layer"], []).append((k, b))
        done, current = set(), None
        held = 0  # bodies of the current layer drawn so far
        for e in entities:
            layer, slash, n = e.id.rpartition("/")
            if not slash or layer not in by_layer or not n.isdigit():
                raise Problem(f"{where}: entity {e.id!r}, not a batch LAYER/K of a layer with bodies on this topic")
            if layer != current:
                if current is not None and held != len(by_layer[current]):
                    raise Problem(f"{where}: layer {current}'s batches hold {held} of its {len(by_layer[current])} bodies")
                if layer in done:
                    raise Problem(f"{where}: layer {layer}'s batches are not together")
                done.add(layer)
                current, held, k = layer, 0, 0
            if n != str(k):
                raise Problem(f"{where}: entity {e.id} where {layer}/{k} was due")
            k += 1
            bodies = by_layer[layer]
            meta = [(kv.key, kv.value) for kv in e.metadata]
            count = int(meta[1][1]) if len(meta) == 4 and meta[1][0] == "bodies" and meta[1][1].isdigit() else 0
            mine = bodies[held:held + count]
            if count == 0 or len(mine) != count:
                raise Problem(f"{where}: entity {e.id} has metadata {meta}, with {len(bodies) - held} bodies of {layer} left")
            name = lambda kb: f"{kb[0][0]}:{kb[0][1]}"
            want = [("layer", layer), ("bodies", str(count)), ("first", name(mine[0])), ("last", name(mine[-1]))]
            if meta != want:
                raise Problem(f"{where}: entity {e.id} has metadata {meta}, the bodies it holds {want}")
            parts = sum(len(shape_parts(b["shape"])) for _, b in mine)
            if parts > CHUNK_PARTS:
                raise Problem(f"{where}: entity {e.id} holds {parts} body parts, over {CHUNK_PARTS}")
            if held + count < len(bodies) and parts + len(shape_parts(bodies[held + count][1]["shape"])) <= CHUNK_PARTS:
                raise Problem(f"{where}: entity {e.id} holds {parts} body parts and the next body would fit")
            compare_drawing(e, mine, f"{where}: entity {e.id}")
            held += count
        if current is not None and held != len(by_layer[current]):
            raise Problem(f"{where}: layer {current}'s batches hold {held} of its {len(by_layer[current])} bodies")
        if done != set(by_layer):
            raise Problem(f"{where}: no batch of layers {sorted(set(by_layer) - done)}")

    def check_view(self, frame, t, m):
        """A `/tf` message: the camera's frame, sent only when it moves."""
        if len(m.transforms) != 1:
            raise Problem(f"/tf frame {frame}: {len(m.transforms)} transforms, expected the view frame alone")
        tf = m.transforms[0]
        tr, q = tf.translation, tf.rotation
        if tf.parent_frame_id != WORLD or tf.child_frame_id != "view" or ts_ns(tf.timestamp) != t:
            raise Problem(f"/tf frame {frame}: {tf.child_frame_id!r} in {tf.parent_frame_id!r} at {ts_ns(tf.timestamp)} ns, expected 'view' in {WORLD!r} at {t} ns")
        if tr.z != 0.0 or (q.x, q.y, q.z, q.w) != (0.0, 0.0, 0.0, 1.0) or not (is_f32(tr.x) and is_f32(tr.y)):
            raise Problem(f"/tf frame {frame}: view at ({tr.x!r}, {tr.y!r}, {tr.z!r}) turned ({q.x}, {q.y}, {q.z}, {q.w}): not upright in the plane at f32 precision")
        if self.view == (tr.x, tr.y):
            raise Problem(f"/tf frame {frame}: the view sent again where it was")
        self.view = (tr.x, tr.y)
        self.views += 1

    def check_contacts(self, frame, t, contacts, sent):
        """`/scene/contacts`: the frame's contact normals in one line list."""
        due = bool(contacts) or self.contacts_shown
        if len(sent) != (1 if due else 0):
            raise Problem(f"/scene/contacts frame {frame}: {len(sent)} messages with {len(contacts)} contacts (the frame before had {'some' if self.contacts_shown else 'none'})")
        self.contacts_shown = bool(contacts)
        if not sent:
            return
        s = sent[0]
        where = f"/scene/contacts frame {frame}"
        e = s.entities[0] if len(s.entities) == 1 else None
        if s.deletions or e is None or e.id != "contacts" or e.frame_id != WORLD or e.frame_locked or ts_ns(e.timestamp) != t or e.HasField("lifetime"):
            raise Problem(f"{where}: not one entity 'contacts' in {WORLD!r} at {t} ns")
        if e.arrows or e.cubes or e.spheres or e.cylinders or e.triangles or e.texts or e.models or len(e.lines) != 1:
            raise Problem(f"{where}: not one line list")
        line = e.lines[0]
        if line.type != 2 or planar(line.pose, where) != (0.0, 0.0, 0.0) or line.indices or line.colors:
            raise Problem(f"{where}: not a LINE_LIST of plain points in world coordinates")
        check_color(line.color, where)
        if not is_f32(line.thickness):
            raise Problem(f"{where}: thickness {line.thickness!r} not at f32 precision")
        want = []
        for c in contacts:
            (x, y), (nx, ny), d = c.point, c.normal, max(c.depth, 0.8)
            want += [(x, y), (x + nx * d, y + ny * d)]
        if len(line.points) != len(want):
            raise Problem(f"{where}: {len(line.points)} points for {len(contacts)} contacts")
        for k, (p, (x, y)) in enumerate(zip(line.points, want)):
            if not (is_f32(p.x) and is_f32(p.y) and p.z == DEPTH and close(p.x, x) and close(p.y, y)):
                end = "point" if k % 2 == 0 else "normal's tip"
                raise Problem(f"{where}: contact {k // 2}'s {end} drawn at ({p.x!r}, {p.y!r}, {p.z!r}), /contacts has ({x!r}, {y!r})")


def check(path, every_frame=False):
    try:
        print(f"{path}: {Log(path, every_frame).check()}")
        return 0
    except Problem as e:
        print(f"{path}: FAILED: {e}")
    except Exception as e:  # a reader's error: a bad CRC, an undecodable message, ...
        print(f"{path}: FAILED: {type(e).__name__}: {e}")
    return 1


if __name__ == "__main__":
    args = sys.argv[1:]
    every_frame = "--draw-every-frame" in args
    logs = [a for a in args if a != "--draw-every-frame"]
    if not logs:
        sys.exit(__doc__)
    failed = sum(check(p, every_frame) for p in logs)
    print(f"check_mcap: {len(logs) - failed} passed, {failed} failed")
    sys.exit(1 if failed else 0)
