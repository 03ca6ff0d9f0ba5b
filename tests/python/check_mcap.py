"""Reads Ricochet logs with the official readers and checks every message of every channel.

Usage: python tests/python/check_mcap.py LOG.mcap [LOG.mcap ...]

Each log is read with the official Python `mcap` reader, every CRC checked (the data
section's, each chunk's, the summary's), and every message is decoded with
`mcap-protobuf-support` from the schema the log embeds. Then:

- Channels: exactly the topics `ricochet run` writes, each with its protobuf schema
  (`/validation` optional), and the summary's message counts match what was read.
- No message has a field its schema does not declare, and each one re-encodes to exactly
  its bytes (canonical protobuf, what a deterministic log must be).
- `/scene`, `/scene/contacts`, `/tf` and `/events` against the OFFICIAL Foxglove schemas
  (the `foxglove-schemas-protobuf` package): the descriptor the log embeds declares the
  same message as the official one (field names, numbers, types, labels, nested types,
  enums), and every message parses with the official class, with no unknown field, into
  the same message field for field (`MessageToDict`) as the decoder's.
- Times: `log_time == publish_time`, nondecreasing through the file, each a whole frame
  (`frame * dt_ns`); `/bodies`, `/contacts` and `/stats` hold one message per frame, the
  frames consecutive from 0, at `frame * dt_ns` (and `/validation`, when recorded);
  timestamps inside messages and `/bodies.time` agree.
- `/bodies`: every body's full state is rebuilt from keyframes and deltas, frame by frame;
  a body appears with every field, bodies are unique by `(id, generation)` (one per id at
  a time, a reused id has a later generation, a removed body never returns), no body
  vanishes without being listed in `removed`, and `/stats.bodies` counts the live bodies.
- `/tf` against `/bodies`: at every frame, exactly the bodies that appeared, moved or
  turned have a transform at that frame, its translation equal to the position (the same
  f64 bits) and its yaw to the angle (within 1e-12); a body still since an older
  transform also gets one at the previous frame with that previous pose (so Foxglove's
  interpolation holds it still); every body's frame is `body/ID:GENERATION` in `world`.
- `/scene` draws exactly the live bodies at every frame, each once, in its own frame, with
  its `/bodies` name.
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
    "/bodies": "ricochet.Bodies",
    "/contacts": "ricochet.Contacts",
    "/stats": "ricochet.Stats",
    "/events": "foxglove.Log",
}
OPTIONAL = {"/validation": "ricochet.Validation"}
PER_FRAME = ("/bodies", "/contacts", "/stats")
WORLD = "world"
YAW_TOLERANCE = 1e-12


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


def yaw(q):
    return 2.0 * math.atan2(q.z, q.w)


class Bodies:
    """Every body's full state, rebuilt from `/bodies` keyframes and deltas."""

    FULL = ("name", "layer", "shape", "static", "angle", "angular_velocity")

    def __init__(self):
        self.live = {}  # (id, generation) -> {field: value}
        self.retired = set()
        self.generation = {}  # id -> latest generation seen

    def apply(self, m, frame):
        """Applies frame `frame`'s message; returns the bodies that appeared, moved or turned."""
        if m.frame != frame:
            raise Problem(f"/bodies frame {m.frame} at frame {frame}")
        if frame == 0 and not m.keyframe:
            raise Problem("/bodies: frame 0 is not a keyframe")
        before = self.live
        removed = set()
        for b in m.removed:
            k = (b.id, b.generation)
            if k in removed:
                raise Problem(f"/bodies frame {frame}: body {k} removed twice")
            removed.add(k)
            # Removed with its last state (angular velocity aside: not kept for removed bodies).
            for f in ("name", "layer", "shape", "static", "angle"):
                if not b.HasField(f):
                    raise Problem(f"/bodies frame {frame}: removed body {k} lacks {f}")
            if len(b.position) != 2 or len(b.velocity) != 2:
                raise Problem(f"/bodies frame {frame}: removed body {k} lacks position or velocity")
            if k in self.retired:
                raise Problem(f"/bodies frame {frame}: body {k} removed again")
        live = {k: v for k, v in before.items() if k not in removed}
        listed = set()
        for b in m.bodies:
            k = (b.id, b.generation)
            if k in listed:
                raise Problem(f"/bodies frame {frame}: body {k} listed twice")
            listed.add(k)
            if k in removed or k in self.retired:
                raise Problem(f"/bodies frame {frame}: body {k} listed after its removal")
            new = k not in live
            if new or m.keyframe:
                missing = [f for f in self.FULL if not b.HasField(f)]
                if len(b.position) != 2 or len(b.velocity) != 2:
                    missing.append("position/velocity")
                if missing:
                    why = "a new body" if new else "a keyframe body"
                    raise Problem(f"/bodies frame {frame}: {why} {k} lacks {', '.join(missing)}")
            if new:
                last = self.generation.get(b.id)
                if last is not None and b.generation <= last:
                    raise Problem(f"/bodies frame {frame}: id {b.id} reused with generation {b.generation}, after {last}")
                if (b.id, last) in live:
                    raise Problem(f"/bodies frame {frame}: body {k} appears while {(b.id, last)} is alive")
                state = {}
            else:
                state = dict(live[k])
            for f in self.FULL:
                if b.HasField(f):
                    state[f] = getattr(b, f)
            if b.position:
                if len(b.position) != 2:
                    raise Problem(f"/bodies frame {frame}: body {k} position {list(b.position)}")
                state["position"] = tuple(b.position)
            if b.velocity:
                if len(b.velocity) != 2:
                    raise Problem(f"/bodies frame {frame}: body {k} velocity {list(b.velocity)}")
                state["velocity"] = tuple(b.velocity)
            live[k] = state
            self.generation[b.id] = max(self.generation.get(b.id, b.generation), b.generation)
        if m.keyframe:
            gone = sorted(set(live) - listed)
            if gone:
                raise Problem(f"/bodies keyframe {frame}: bodies {gone[:5]} vanished without being listed in removed")
        for k in removed:
            self.retired.add(k)
            self.generation[k[0]] = max(self.generation.get(k[0], k[1]), k[1])
        moved = set()
        for k in listed:  # a body not listed keeps its state
            s, old = live[k], before.get(k)
            if old is None or bits(*old["position"], old["angle"]) != bits(*s["position"], s["angle"]):
                moved.add(k)
        self.live = live
        return before, moved


class Log:
    def __init__(self, path):
        self.path = path
        self.counts = Counter()
        self.dt_ns = None
        self.frames = 0
        self.bodies = Bodies()
        self.last_tf = {}  # body -> frame of its last transform
        self.scene = None  # the entities of the last /scene, by id
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
        total = sum(self.counts.values())
        per_topic = ", ".join(f"{t} {self.counts[t]}" for t in list(EXPECTED) + list(OPTIONAL) if t in EXPECTED or t in self.counts)
        extra = f" ({self.validation_mismatches} mismatches)" if self.validation else ""
        return (f"ok, CRCs checked, {self.frames} frames of {self.dt_ns or 0} ns, {len(self.bodies.live)} bodies at the end, "
                f"{total} messages: {per_topic}{extra}")

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
        b = msgs["/bodies"][0]
        if abs(b.time * 1e9 - t) > 0.5 * frame + 1e-12 * t + 1e-6:
            raise Problem(f"/bodies frame {frame}: time {b.time!r} s, log_time {t} ns")
        before, moved = self.bodies.apply(b, frame)
        live = self.bodies.live
        names = {f"body/{i}:{g}": (i, g) for i, g in live}
        stats = msgs["/stats"][0]
        if stats.bodies != len(live):
            raise Problem(f"/stats frame {frame}: {stats.bodies} bodies, /bodies rebuilds {len(live)}")
        contacts = len(msgs["/contacts"][0].contacts)
        if stats.contacts != contacts:
            raise Problem(f"/stats frame {frame}: {stats.contacts} contacts, /contacts lists {contacts}")
        # /tf: exactly the bodies that appeared, moved or turned, at their exact poses.
        now, prev = set(), set()
        for tf in (x for m in msgs.get("/tf", []) for x in m.transforms):
            stamp = ts_ns(tf.timestamp)
            name = tf.child_frame_id
            if tf.parent_frame_id != WORLD:
                raise Problem(f"/tf frame {frame}: {name} has parent {tf.parent_frame_id!r}, not {WORLD!r}")
            k = names.get(name)
            if stamp == t:
                if k is None:
                    raise Problem(f"/tf frame {frame}: a transform of {name}, which is not a live body")
                target, state = now, live[k]
            elif frame > 0 and stamp == t - dt:
                if k is None or k not in before:
                    raise Problem(f"/tf frame {frame}: a transform at the previous frame of {name}, not a body then")
                target, state = prev, before[k]
            else:
                raise Problem(f"/tf frame {frame}: {name} stamped {stamp} ns")
            if k in target:
                raise Problem(f"/tf frame {frame}: two transforms of {name} at {stamp} ns")
            target.add(k)
            tr, q = tf.translation, tf.rotation
            x, y = state["position"]
            if bits(tr.x, tr.y, tr.z) != bits(x, y, 0.0):
                raise Problem(f"/tf frame {frame}: {name} at ({tr.x!r}, {tr.y!r}, {tr.z!r}) stamped {stamp} ns, /bodies has ({x!r}, {y!r})")
            if q.x != 0.0 or q.y != 0.0 or abs(q.z * q.z + q.w * q.w - 1.0) > 1e-12:
                raise Problem(f"/tf frame {frame}: {name} rotation ({q.x}, {q.y}, {q.z}, {q.w}) is not a unit yaw")
            err = math.remainder(yaw(q) - state["angle"], math.tau)
            if not abs(err) <= YAW_TOLERANCE:
                raise Problem(f"/tf frame {frame}: {name} yaw {yaw(q)!r}, /bodies angle {state['angle']!r} (off by {err:.3g})")
        if now != moved:
            missing, extra = sorted(moved - now), sorted(now - moved)
            raise Problem(f"/tf frame {frame}: no transform of {missing[:5]}, which appeared or moved; transforms of {extra[:5]}, which did not")
        for k in now:
            held = k in before and self.last_tf[k] + 1 < frame
            if held != (k in prev):
                raise Problem(f"/tf frame {frame}: body {k}, last sent at frame {self.last_tf.get(k)}, has {'no' if held else 'a'} transform at the previous frame")
            self.last_tf[k] = frame
        if prev - now:
            raise Problem(f"/tf frame {frame}: transforms at the previous frame of bodies that did not move {sorted(prev - now)[:5]}")
        for k in [k for k in self.last_tf if k not in live]:
            del self.last_tf[k]
        # /scene: its last message is the whole scene, every live body in its own frame.
        for s in msgs.get("/scene", []):
            if [d.type for d in s.deletions] != [1] or ts_ns(s.deletions[0].timestamp) != t:
                raise Problem(f"/scene frame {frame}: not a delete-all at {t} ns, then the scene")
            self.scene = {}
            for e in s.entities:
                if e.id in self.scene or e.frame_id != e.id or not e.frame_locked or ts_ns(e.timestamp) != t:
                    raise Problem(f"/scene frame {frame}: entity {e.id} (frame {e.frame_id}, locked {e.frame_locked}) is not a body drawn once in its own frame at {t} ns")
                names_meta = [kv.value for kv in e.metadata if kv.key == "name"]
                if e.id in names and names_meta != [live[names[e.id]]["name"]]:
                    raise Problem(f"/scene frame {frame}: entity {e.id} named {names_meta}, /bodies names it {live[names[e.id]]['name']!r}")
                self.scene[e.id] = e
        drawn = set(self.scene or ())
        if drawn != set(names):
            raise Problem(f"/scene at frame {frame}: draws {sorted(drawn - set(names))[:5]}, not live bodies; does not draw {sorted(set(names) - drawn)[:5]}")
        for s in msgs.get("/scene/contacts", []):
            if any(ts_ns(e.timestamp) != t or e.frame_id != WORLD for e in s.entities):
                raise Problem(f"/scene/contacts frame {frame}: an entity not at {t} ns in {WORLD!r}")
        for e in msgs.get("/events", []):
            if ts_ns(e.timestamp) != t:
                raise Problem(f"/events frame {frame}: stamped {ts_ns(e.timestamp)} ns at {t} ns")


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
