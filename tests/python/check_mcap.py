"""Reads a Ricochet log with the official Python `mcap` reader, CRCs checked, and with the
`jsonschema` package validates every message against the schema its channel embeds (for
/scene and /events, the official Foxglove schemas vendored from @foxglove/schemas 2.1.0).

Usage: python tests/python/check_mcap.py LOG.mcap [LOG.mcap ...]
Exits 1 on any problem. Run by .ci/run on the log `ricochet run` writes with no arguments.
"""

import json
import sys

import jsonschema
from mcap.reader import make_reader

EXPECTED = {
    "/scene": "foxglove.SceneUpdate",
    "/bodies": "ricochet.Bodies",
    "/contacts": "ricochet.Contacts",
    "/stats": "ricochet.Stats",
    "/events": "foxglove.Log",
}


def check(path: str) -> int:
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        if summary is None or summary.statistics is None:
            print(f"{path}: no summary or statistics: the log is not indexed")
            return 1
        topics = {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values()}
        if topics != EXPECTED:
            print(f"{path}: channels {topics}, expected {EXPECTED}")
            return 1
        validators = {}
        counts = {t: 0 for t in EXPECTED}
        last_time = -1
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            if channel.topic not in validators:
                validators[channel.topic] = jsonschema.validators.validator_for(json.loads(schema.data))(json.loads(schema.data))
            data = json.loads(message.data)
            errors = sorted(validators[channel.topic].iter_errors(data), key=str)
            if errors:
                print(f"{path}: {channel.topic} at {message.log_time} ns: {errors[0].message}")
                return 1
            if message.log_time != message.publish_time or message.log_time < last_time:
                print(f"{path}: {channel.topic}: times out of order or log != publish")
                return 1
            last_time = message.log_time
            counts[channel.topic] += 1
        total = sum(counts.values())
        if total != summary.statistics.message_count:
            print(f"{path}: read {total} messages, the summary says {summary.statistics.message_count}")
            return 1
        print(f"{path}: ok, CRCs checked, {total} messages: " + ", ".join(f"{t} {n}" for t, n in counts.items()))
    return 0


if __name__ == "__main__":
    sys.exit(max(check(p) for p in sys.argv[1:]))
