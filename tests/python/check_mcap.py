"""Reads Ricochet logs with the official readers and checks every message of every channel.

Usage: python tests/python/check_mcap.py LOG.mcap [LOG.mcap ...]

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
  add), unless `still`; unlisted velocities are unchanged. A body that appears, and every
  body of a keyframe, has every field; a removed body has every field (its angular
  velocity too) and, if it was alive, its name, layer, shape and kind; a delta neither
  changes what only full listings carry nor sets `still` with a position or an angle.
  Bodies are unique by `(id, generation)` (one per id at a time, a reused id has a later
  generation, a removed body never returns), no body vanishes without being listed in
  `removed`, and `/stats.bodies` counts the live bodies.
- `/tf` against `/bodies`, as Foxglove shows it: every transform is a body's frame
  `body/ID:GENERATION` in `world`, planar (z = 0, a unit quaternion about z), stamped at a
  frame's time (a multiple of `dt_ns`), never before its message's `log_time` (it may be
  after: a prediction), the first one at the frame the body appeared; one stamped at its
  message's own time (an exact pose) has the body's `/bodies` position at that frame to the
  bit. Then at EVERY frame and for every live body, Foxglove's lookup of its frame at that
  frame's time, from the transform messages logged at or before it (Lichtblick never reads
  preloaded messages ahead of the time shown; a later transform with the same timestamp
  replaces the earlier): the transform stamped then, else the position lerped and the
  rotation slerped between the transforms before and after, gl-matrix style; before the
  first or after the last, that one. It must be the body's `/bodies` pose: x and y within
  1e-9 of max(1, |value|), the angle within 1e-9 rad modulo a turn (0 for a body with an AABB part, whose frame stays
  upright). `/tf` sends a body on
  a straight line only as a prediction ahead, overwritten when the motion changes, so
  this fails if a prediction is wrong and not overwritten in time, or turns too far to
  slerp.
- `/scene` and `/scene/static` together draw exactly the live bodies at every frame, each once, in its own frame, with
  its `/bodies` name.
- `/contacts` and `/stats` agree on the number of contacts.

Prints one line per log, then `check_mcap: N passed, N failed`; exits 1 on any problem,
naming it.
"""

import bisect
import importlib
import math
import re
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
BODY_FRAME = re.compile(r"body/(\d+):(\d+)")
# A /tf transform's rotation is a unit quaternion (within f64 rounding of sin² + cos²).
UNIT_TOLERANCE = 1e-12
# Foxglove's interpolated pose against /bodies: relative to max(1, |value|) for x and y,
# absolute (radians, modulo a turn) for the angle.
POSE_TOLERANCE = 1e-9
# gl-matrix quat.slerp: below this 1 - cos, a plain lerp.
SLERP_EPSILON = 1e-6


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


def has_aabb(shape):
    """Whether a `ricochet.Shape` has an AABB part."""
    kind = shape.WhichOneof("kind")
    return kind == "aabb" or (kind == "compound" and any(has_aabb(p) for p in shape.compound.parts))


class Bodies:
    """Every body's full state, rebuilt from `/bodies` keyframes and deltas as `BodyStates`
    (crates/log/src/bodies.rs) does, and every body's pose at every frame it was alive."""

    # Carried only when a body is listed in full (it appears, or a keyframe).
    FIXED = ("name", "layer", "shape", "static")
    FULL = FIXED + ("angle", "angular_velocity")

    def __init__(self):
        self.live = {}  # (id, generation) -> {field: value}
        self.retired = set()
        self.generation = {}  # id -> latest generation seen
        self.dt = None
        # (id, generation) -> (first frame alive, [(x, y, angle) at each frame since])
        self.history = {}

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
                if b.velocity:
                    state["velocity"] = tuple(b.velocity)
                if b.HasField("angular_velocity"):
                    state["angular_velocity"] = b.angular_velocity
                if b.still:
                    live[k] = state
                    continue
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
                self.history[k] = (frame, [])
            elif m.keyframe:
                for f in self.FIXED:
                    if getattr(b, f) != before[k][f]:
                        raise Problem(f"/bodies keyframe {frame}: body {k} has {f} {getattr(b, f)!r}, the frame before {before[k][f]!r}")
            state = {f: getattr(b, f) for f in self.FULL}
            state["position"] = tuple(b.position)
            state["velocity"] = tuple(b.velocity)
            live[k] = state
            self.generation[b.id] = max(self.generation.get(b.id, b.generation), b.generation)
        for k in removed:
            self.retired.add(k)
            self.generation[k[0]] = max(self.generation.get(k[0], k[1]), k[1])
        for k, s in live.items():
            # A body with an AABB part (which does not turn) has an upright frame.
            angle = 0.0 if has_aabb(s["shape"]) else s["angle"]
            self.history[k][1].append((*s["position"], angle))
        self.live = live


def slerp_yaw(a, b, f):
    """gl-matrix `quat.slerp(a, b, f)` of two quaternions (x, y, z, w), as a yaw."""
    cos = sum(p * q for p, q in zip(a, b))
    if cos < 0.0:
        cos, b = -cos, tuple(-q for q in b)
    if 1.0 - cos > SLERP_EPSILON:
        omega = math.acos(cos)
        s = math.sin(omega)
        s0, s1 = math.sin((1.0 - f) * omega) / s, math.sin(f * omega) / s
    else:
        s0, s1 = 1.0 - f, f
    z = s0 * a[2] + s1 * b[2]
    w = s0 * a[3] + s1 * b[3]
    return 2.0 * math.atan2(z, w)


class Transform:
    """One `/tf` transform of a body's frame."""

    __slots__ = ("stamp", "log_time", "x", "y", "q")

    def __init__(self, tf, log_time):
        self.stamp = ts_ns(tf.timestamp)
        self.log_time = log_time
        self.x, self.y = tf.translation.x, tf.translation.y
        r = tf.rotation
        self.q = (r.x, r.y, r.z, r.w)

    def pose(self):
        return self.x, self.y, 2.0 * math.atan2(self.q[2], self.q[3])


def foxglove_pose(transforms, stamps, t):
    """The pose Foxglove's 3D panel gives a frame at `t` from the transforms it holds
    (`stamps` their sorted timestamps): the one stamped `t`; between two, the translation
    lerped and the rotation slerped; before the first or after the last, that one. Also
    the indices of the transforms used."""
    i = bisect.bisect_left(stamps, t)
    if i < len(stamps) and stamps[i] == t:
        return transforms[i].pose(), (i, i)
    if i == 0:
        return transforms[0].pose(), (0, 0)
    if i == len(stamps):
        return transforms[-1].pose(), (i - 1, i - 1)
    a, b = transforms[i - 1], transforms[i]
    f = (t - a.stamp) / (b.stamp - a.stamp)
    x = a.x + f * (b.x - a.x)  # gl-matrix vec3.lerp
    y = a.y + f * (b.y - a.y)
    return (x, y, slerp_yaw(a.q, b.q, f)), (i - 1, i)


def pose_error(got, want):
    """(x and y error relative to max(1, |value|), angle error modulo a turn); NaN counts
    as infinitely wrong."""
    ex = max(abs(g - w) / max(1.0, abs(w)) for g, w in zip(got[:2], want[:2]))
    ea = abs(math.remainder(got[2] - want[2], math.tau))
    return tuple(e if e == e else math.inf for e in (ex, ea))


def round_ns(seconds):
    """Rust's `(seconds * 1e9).round() as u64`: half away from zero."""
    v = seconds * 1e9
    r = math.floor(v)
    return int(r) + (1 if v - r >= 0.5 else 0)


class Log:
    def __init__(self, path):
        self.path = path
        self.counts = Counter()
        self.dt_ns = None
        self.frames = 0
        self.bodies = Bodies()
        self.tf = {}  # child frame -> [Transform], in file order
        self.tf_summary = ""
        self.scenes = {}  # topic -> the entities of its last message, by id
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
                group.setdefault(topic, []).append(decoded)
            if not group:
                raise Problem("no message")
            self.frame(group_time, group)
            stats = summary.statistics
            if sum(self.counts.values()) != stats.message_count:
                raise Problem(f"read {sum(self.counts.values())} messages, the summary says {stats.message_count}")
            for c in summary.channels.values():
                if stats.channel_message_counts.get(c.id, 0) != self.counts[c.topic]:
                    raise Problem(f"{c.topic}: read {self.counts[c.topic]} messages, the summary says {stats.channel_message_counts.get(c.id, 0)}")
        self.check_tf()
        total = sum(self.counts.values())
        per_topic = ", ".join(f"{t} {self.counts[t]}" for t in list(EXPECTED) + list(OPTIONAL) if t in EXPECTED or t in self.counts)
        extra = f" ({self.validation_mismatches} mismatches)" if self.validation else ""
        return (f"ok, CRCs checked, {self.frames} frames of {self.dt_ns or 0} ns, {len(self.bodies.live)} bodies at the end, "
                f"{total} messages: {per_topic}{extra}; {self.tf_summary}")

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
        names = {f"body/{i}:{g}": (i, g) for i, g in live}
        stats = msgs["/stats"][0]
        if stats.bodies != len(live):
            raise Problem(f"/stats frame {frame}: {stats.bodies} bodies, /bodies rebuilds {len(live)}")
        contacts = len(msgs["/contacts"][0].contacts)
        if stats.contacts != contacts:
            raise Problem(f"/stats frame {frame}: {stats.contacts} contacts, /contacts lists {contacts}")
        # /tf: kept (preloaded, as Foxglove does) and checked against /bodies at the end.
        for m in msgs.get("/tf", []):
            if not m.transforms:
                raise Problem(f"/tf frame {frame}: an empty message")
            for tf in m.transforms:
                name = tf.child_frame_id
                if tf.parent_frame_id != WORLD:
                    raise Problem(f"/tf frame {frame}: {name} has parent {tf.parent_frame_id!r}, not {WORLD!r}")
                if not BODY_FRAME.fullmatch(name):
                    raise Problem(f"/tf frame {frame}: a transform of {name!r}, not a body's frame body/ID:GENERATION")
                tr, q = tf.translation, tf.rotation
                if tr.z != 0.0 or q.x != 0.0 or q.y != 0.0 or not abs(q.z * q.z + q.w * q.w - 1.0) <= UNIT_TOLERANCE:
                    raise Problem(f"/tf frame {frame}: {name} at ({tr.x!r}, {tr.y!r}, {tr.z!r}) turned ({q.x}, {q.y}, {q.z}, {q.w}): not planar (z = 0, a unit yaw quaternion)")
                x = Transform(tf, t)
                if x.stamp < t:
                    raise Problem(f"/tf frame {frame}: {name} stamped {x.stamp} ns, before its message ({t} ns)")
                self.tf.setdefault(name, []).append(x)
        # /scene and /scene/static: the last message of each is the whole of its bodies
        # (moving, static), every one in its own frame.
        for topic in ("/scene", "/scene/static"):
            for s in msgs.get(topic, []):
                if [d.type for d in s.deletions] != [1] or ts_ns(s.deletions[0].timestamp) != t:
                    raise Problem(f"{topic} frame {frame}: not a delete-all at {t} ns, then the scene")
                scene = {}
                for e in s.entities:
                    if e.id in scene or e.frame_id != e.id or not e.frame_locked or ts_ns(e.timestamp) != t:
                        raise Problem(f"{topic} frame {frame}: entity {e.id} (frame {e.frame_id}, locked {e.frame_locked}) is not a body drawn once in its own frame at {t} ns")
                    names_meta = [kv.value for kv in e.metadata if kv.key == "name"]
                    if e.id in names and names_meta != [live[names[e.id]]["name"]]:
                        raise Problem(f"{topic} frame {frame}: entity {e.id} named {names_meta}, /bodies names it {live[names[e.id]]['name']!r}")
                    if e.id in names and live[names[e.id]]["static"] != (topic == "/scene/static"):
                        raise Problem(f"{topic} frame {frame}: entity {e.id} is drawn on the wrong topic for its kind")
                    scene[e.id] = e
                self.scenes[topic] = scene
        drawn = [i for scene in self.scenes.values() for i in scene]
        if len(drawn) != len(set(drawn)):
            raise Problem(f"/scene at frame {frame}: a body drawn on both /scene and /scene/static")
        drawn = set(drawn)
        if drawn != set(names):
            raise Problem(f"/scene at frame {frame}: draws {sorted(drawn - set(names))[:5]}, not live bodies; does not draw {sorted(set(names) - drawn)[:5]}")
        for s in msgs.get("/scene/contacts", []):
            if any(ts_ns(e.timestamp) != t or e.frame_id != WORLD for e in s.entities):
                raise Problem(f"/scene/contacts frame {frame}: an entity not at {t} ns in {WORLD!r}")
        for e in msgs.get("/events", []):
            if ts_ns(e.timestamp) != t:
                raise Problem(f"/events frame {frame}: stamped {ts_ns(e.timestamp)} ns at {t} ns")

    def check_tf(self):
        """Every body's frame, as Foxglove shows it from the `/tf` messages logged by then,
        against `/bodies` at every frame the body is alive."""
        dt_ns = self.dt_ns or 0
        last = (self.frames - 1) * dt_ns
        history = self.bodies.history
        frame_ids = {f"body/{i}:{g}": (i, g) for i, g in history}
        strays = sorted(set(self.tf) - set(frame_ids))
        if strays:
            raise Problem(f"/tf: transforms of {strays[:5]}, never a body in /bodies")

        def at(stamp):
            return stamp // dt_ns if dt_ns else 0

        worst = [0.0, 0.0]
        checked = bad = 0
        off = []  # (frame, body frame, what is wrong): the first of each body
        for name, k in frame_ids.items():
            first, poses = history[k]
            gone = first + len(poses) - 1  # the last frame it is alive
            sent = self.tf.get(name, [])  # in file order: by log time
            if not sent:
                raise Problem(f"/tf: no transform of {name}, alive at frames {first} to {gone}")
            for x in sent:
                f = at(x.stamp)
                if x.stamp != f * dt_ns:
                    raise Problem(f"/tf: {name} stamped {x.stamp} ns (sent at {x.log_time} ns), not a frame's time (a multiple of {dt_ns} ns)")
                if x.stamp == x.log_time:  # an exact pose: the body's position, to the bit
                    if not first <= f <= gone:
                        raise Problem(f"/tf: {name} at frame {f}, alive only at frames {first} to {gone}")
                    want = poses[f - first]
                    if bits(x.x, x.y) != bits(*want[:2]):
                        raise Problem(f"/tf: {name} at frame {f} at ({x.x!r}, {x.y!r}), /bodies rebuilds ({want[0]!r}, {want[1]!r})")
            if sent[0].stamp != first * dt_ns:
                raise Problem(f"/tf: the first transform of {name} is at frame {at(sent[0].stamp)}, it appeared at frame {first}")
            # What Foxglove holds at each frame: the transforms logged by then, by stamp.
            held, stamps, read = {}, [], 0
            for i, want in enumerate(poses):
                frame = first + i
                t = frame * dt_ns
                while read < len(sent) and sent[read].log_time <= t:
                    x = sent[read]
                    if x.stamp not in held:
                        bisect.insort(stamps, x.stamp)
                    held[x.stamp] = x
                    read += 1
                tfs = [held[st] for st in stamps]
                got, (a, b) = foxglove_pose(tfs, stamps, t)
                ex, ea = pose_error(got, want)
                checked += 1
                worst = [max(worst[0], ex), max(worst[1], ea)]
                if not (ex <= POSE_TOLERANCE and ea <= POSE_TOLERANCE):
                    bad += 1
                    if off and off[-1][1] == name:
                        continue  # the first of each body is enough
                    if a == b and stamps[a] == t:
                        how = "its transform stamped then"
                    elif a == b:
                        side = "before its first" if stamps[a] > t else "after its last"
                        how = f"{side} transform, at frame {at(stamps[a])}, held"
                    else:
                        how = f"interpolated between its transforms at frames {at(stamps[a])} and {at(stamps[b])}"
                    g = ", ".join(f"{v!r}" for v in got)
                    w = ", ".join(f"{v!r}" for v in want)
                    off.append((frame, name, f"shown at (x, y, angle) ({g}), {how}; /bodies has ({w}): off by {ex:.3g} relative, {ea:.3g} rad"))
        if off:
            frame, name, what = min(off)
            raise Problem(f"/tf: {bad} body-frames of {len(off)} bodies not shown where /bodies has them; the first, at frame {frame} ({frame * dt_ns} ns): {name} {what}")
        n = sum(len(v) for v in self.tf.values())
        self.tf_summary = (f"/tf: {n} transforms give {checked} body-frames, "
                           f"worst {worst[0]:.1e} (position, relative), {worst[1]:.1e} rad")


def check(path):
    try:
        print(f"{path}: {Log(path).check()}")
        return 0
    except Problem as e:
        print(f"{path}: FAILED: {e}")
    except Exception as e:  # a reader's error: a bad CRC, an undecodable message, ...
        print(f"{path}: FAILED: {type(e).__name__}: {e}")
    return 1


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    failed = sum(check(p) for p in sys.argv[1:])
    print(f"check_mcap: {len(sys.argv) - 1 - failed} passed, {failed} failed")
    sys.exit(1 if failed else 0)
