#!/usr/bin/env python3
"""Generates a suite of N small scenario variants for `ricochet test` (the scale test of
BENCHMARKS.md, and the cluster run of scripts/cluster-ci.sh).

    python3 scripts/gen_suite.py N DIR [--frames F]

Variant i is shipped scenario i mod S (the S files of scenarios/*.toml, sorted), cut to F
frames (default 60: one second at 60 Hz; its later script events dropped), with every
`velocity = [x, y]` and `gravity = [x, y]` line scaled by 1 + (i // S) / 1000, so no two
variants record the same log. It writes DIR/NAME-IIII.toml, and copies scenarios/maps/ (the
Tiled maps a shipped level reads) to DIR/maps/; nothing else: bless them
with `ricochet test DIR --bless` (goldens in recordings/ beside DIR). The same N and F
always give the same files.
"""

import argparse
import shutil
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NUMBER = r"\s*([-0-9.eE+]+)\s*"
VELOCITY = re.compile(rf"^(\s*(?:velocity|gravity)\s*=\s*)\[{NUMBER},{NUMBER}\]", re.M)
FRAMES = re.compile(r"^frames\s*=\s*\d+", re.M)
NAME = re.compile(r'^name\s*=\s*"[^"]*"', re.M)
INLINE_EVENT = re.compile(r"^\s*\{\s*frame\s*=\s*(\d+)")
EVENT_FRAME = re.compile(r"^frame\s*=\s*(\d+)")


def drop_late_events(text, frames):
    """`text` without the script events after the last frame (`ricochet check` rejects
    them): inline `{ frame = N, ... }` lines and whole `[[script]]` tables."""
    out = []
    table = None  # the lines of the [[script]] table being read
    for line in text.splitlines(keepends=True):
        if table is not None:
            if line.startswith("["):
                out.extend(flush(table, frames))
                table = None
            else:
                table.append(line)
                continue
        if line.strip() == "[[script]]":
            table = [line]
            continue
        m = INLINE_EVENT.match(line)
        if m and int(m.group(1)) > frames:
            continue
        out.append(line)
    if table is not None:
        out.extend(flush(table, frames))
    return "".join(out)


def flush(table, frames):
    """A [[script]] table's lines, or none if its event comes after the last frame."""
    for line in table:
        m = EVENT_FRAME.match(line)
        if m and int(m.group(1)) > frames:
            return []
    return table


def variant(text, name, frames, scale):
    """The scenario `text` renamed, cut to `frames` and with its velocities scaled."""
    text, n = FRAMES.subn(f"frames = {frames}", text, count=1)
    if n != 1:
        raise ValueError(f"{name}: no top-level `frames = N` line")
    text = NAME.sub(f'name = "{name}"', text, count=1)

    def scaled(m):
        x, y = (float(v) * scale for v in (m.group(2), m.group(3)))
        return f"{m.group(1)}[{x!r}, {y!r}]"

    return drop_late_events(VELOCITY.sub(scaled, text), frames)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("count", type=int, help="how many variants")
    p.add_argument("dir", type=Path, help="the folder to write them in (created)")
    p.add_argument("--frames", type=int, default=60, help="frames per variant (default 60)")
    args = p.parse_args()
    if args.count < 1 or args.frames < 1:
        sys.exit("error: N and --frames must be at least 1")
    sources = sorted((ROOT / "scenarios").glob("*.toml"))
    texts = [(s.stem, s.read_text(encoding="utf-8")) for s in sources]
    args.dir.mkdir(parents=True, exist_ok=True)
    width = max(4, len(str(args.count - 1)))
    for i in range(args.count):
        stem, text = texts[i % len(texts)]
        name = f"{stem}-{i:0{width}d}"
        scale = 1 + (i // len(texts)) / 1000
        out = variant(text, name, args.frames, scale)
        (args.dir / f"{name}.toml").write_text(out, encoding="utf-8")
    # A Tiled level's map, relative to its scenario file.
    maps = ROOT / "scenarios" / "maps"
    if maps.is_dir():
        shutil.copytree(maps, args.dir / "maps", dirs_exist_ok=True)
    print(f"{args.count} scenarios in {args.dir}", file=sys.stderr)


if __name__ == "__main__":
    main()
