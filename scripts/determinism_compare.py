#!/usr/bin/env python3
"""The determinism gate's verdict: compares the per-frame checksums that ricochet-portable
printed on each target (see crates/portable/src/lib.rs for the format), and the final
digests against recordings/*.digest.

    determinism_compare.py RECORDINGS REF_LABEL REF_OUT [LABEL OUT | --partial LABEL OUT]...

The first output is the reference (x86-64). Every other output must hold the same scenes,
or with --partial a subset of them (the browser example steps one scene), each frame
equal. The first differing frame is named with its scene and both targets, and the exit
code is 1. Exit 2 for an output that is not the gate's format.
"""

import sys
from pathlib import Path


def parse(label, path):
    """scene name -> (header, [frame lines], end line), in file order."""
    scenes, current = {}, None
    for n, line in enumerate(Path(path).read_text().splitlines(), 1):
        words = line.split()
        if words and words[0] == "scene":
            current = words[1]
            scenes[current] = [line, [], None]
        elif words and words[0] == "end" and current == words[1]:
            scenes[current][2] = line
            current = None
        elif current is not None and len(words) == 3:
            scenes[current][1].append(line)
        else:
            sys.exit(f"{label} ({path}) line {n}: not the gate's format: {line!r}")
    for name, (_, _, end) in scenes.items():
        if end is None:
            sys.exit(f"{label} ({path}): scene {name} has no end line (did the run stop?)")
    return scenes


def first_difference(ref, other):
    """The first (frame, ref line, other line) where two scenes differ, or None."""
    ref_head, ref_frames, ref_end = ref
    head, frames, end = other
    if ref_head != head:
        return ("header", ref_head, head)
    for a, b in zip(ref_frames, frames):
        if a != b:
            return (a.split()[0], a, b)
    if len(ref_frames) != len(frames):
        return (f"{min(len(ref_frames), len(frames))} (one run stopped)", "", "")
    if ref_end != end:
        return ("end", ref_end, end)
    return None


def main(argv):
    recordings, ref_label, ref_path, rest = Path(argv[0]), argv[1], argv[2], argv[3:]
    ref = parse(ref_label, ref_path)
    failed = False
    while rest:
        partial = rest[0] == "--partial"
        if partial:
            rest = rest[1:]
        label, path, rest = rest[0], rest[1], rest[2:]
        other = parse(label, path)
        if not partial and list(other) != list(ref):
            print(f"determinism gate: {label} ran scenes {list(other)}, {ref_label} {list(ref)}")
            failed = True
            continue
        frames = 0
        for name, scene in other.items():
            if name not in ref:
                print(f"determinism gate: {label} ran scene {name}, which {ref_label} did not")
                failed = True
                break
            diff = first_difference(ref[name], scene)
            if diff:
                frame, a, b = diff
                print(
                    f"determinism gate: scenario {name}, frame {frame}: {ref_label} and {label} differ\n"
                    f"  {ref_label:>8}: {a}\n  {label:>8}: {b}"
                )
                failed = True
                break
            frames += len(scene[1])
        else:
            print(f"{label}: {len(other)} scenes, {frames} frames, every checksum equal to {ref_label}")
    # The final states of the shipped scenarios against their checked-in digests.
    checked = 0
    for digest in sorted(recordings.glob("*.digest")):
        name = digest.stem
        if name not in ref:
            print(f"determinism gate: {digest} has no scenario in the run")
            failed = True
            continue
        words = ref[name][2].split()
        got = f"frames {words[3]}\nbodies {words[5]}\nhash {words[7]}\n"
        if got != digest.read_text():
            print(f"determinism gate: scenario {name}: final digest\n{got}differs from {digest}")
            failed = True
        checked += 1
    print(f"recordings: {checked} final digests equal to recordings/*.digest")
    return 1 if failed else 0


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1:]))
