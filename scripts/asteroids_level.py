#!/usr/bin/env python3
"""Print a TOML scenario of N asteroids: the 10,000-asteroid level of issue #12 ("Logs at scale").

    python3 scripts/asteroids_level.py 10000 > /tmp/level10k.toml
    ricochet check /tmp/level10k.toml
    ricochet run /tmp/level10k.toml -o /tmp/level10k.mcap

Half the asteroids are circles, half convex counter-clockwise 5- to 8-gons (vertices on a
circle at jittered angles), radius 0.5 to 3; random positions in a 2000 x 2000 wrap-around
world, speeds 0.5 to 5 units/s in a random direction, spins -1 to 1 rad/s, random angles.
They share one layer that ignores itself (like the rocks of scenarios/asteroids.toml), so
nothing collides and all N bodies move for the whole run: 600 frames at 60 Hz, no script,
no gravity. Seeded (--seed, default 12): the same N and seed print the same file, byte for
byte, on any machine (Python's `random` is Mersenne Twister; floats are printed with
`repr`, which round-trips exactly).

--nudge K changes asteroid K's x velocity by one ulp (math.nextafter towards +inf) and
nothing else: a log of it differs from the plain level's from frame 0 on, in that body
only (for testing `ricochet diff`).

--firing adds a game's ship: at the world's centre, turning and firing a bullet every third
frame (bullets live 60 frames and destroy the asteroid they hit, both removed), so bodies
come and go every few frames and the small layers (the ship and its bullets) are a cluster
in a big field, as in a real Asteroids game.

Standard library only; the format is the one of scenarios/README.md, which both the JSON-log
(891484c) and the protobuf-log binaries load.
"""

import argparse
import math
import random
import sys

SIDE = 2000.0
HZ = 60
FRAMES = 600


def num(x: float) -> str:
    """A TOML float that reads back as exactly `x`."""
    r = repr(float(x))
    if r in ("inf", "-inf", "nan"):
        raise ValueError(f"not finite: {r}")
    return r


def polygon(rng: random.Random, sides: int, radius: float) -> list:
    """Convex CCW: points on a circle at increasing angles, each jittered by at most a
    quarter step (so neighbours stay at least half a step apart). Rounded to 1e-6; at
    radius >= 0.5 and steps >= 45 degrees that cannot break convexity."""
    step = 2.0 * math.pi / sides
    phase = rng.uniform(0.0, step)
    pts = []
    for k in range(sides):
        a = phase + step * k + rng.uniform(-0.25, 0.25) * step
        pts.append((round(math.cos(a) * radius, 6), round(math.sin(a) * radius, 6)))
    return pts


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", type=int, help="number of asteroids (>= 1)")
    ap.add_argument("--seed", type=int, default=12, help="random seed (default 12)")
    ap.add_argument("--frames", type=int, default=FRAMES, help=f"frames (default {FRAMES})")
    ap.add_argument(
        "--nudge",
        type=int,
        metavar="K",
        help="change asteroid K's x velocity by one ulp (0-based)",
    )
    ap.add_argument(
        "--firing",
        action="store_true",
        help="add a ship at the centre turning and firing every third frame",
    )
    args = ap.parse_args()
    if args.n < 1:
        ap.error("n must be at least 1")
    if args.nudge is not None and not 0 <= args.nudge < args.n:
        ap.error(f"--nudge must be 0 to {args.n - 1}")

    rng = random.Random(args.seed)
    out = []
    w = out.append
    w(f"# {args.n} asteroids (scripts/asteroids_level.py {args.n} --seed {args.seed}"
      + (f" --nudge {args.nudge}" if args.nudge is not None else "")
      + (" --firing" if args.firing else "") + ")")
    w(f'name = "asteroids-level-{args.n}' + ("-firing" if args.firing else "") + '"')
    w(f"hz = {HZ}")
    w(f"frames = {args.frames}")
    if args.firing:
        w('layers = ["ship", "asteroid", "bullet"]')
        w('fast_layers = ["bullet"]')
        w("script = [")
        w('  { frame = 0, action = "turn", body = "ship", input = 1 },')
        for f in range(1, args.frames, 3):
            w(f'  {{ frame = {f}, action = "fire", body = "ship" }},')
        w("]")
    else:
        w('layers = ["asteroid"]')
    w("")
    w("[world]")
    w("gravity = [0, 0]")
    w(f"bounds = {{ min = [0, 0], max = [{num(SIDE)}, {num(SIDE)}], wrap = true }}")
    w("")
    w("# Asteroids pass through each other (never tested).")
    w("[[collide]]")
    w('a = "asteroid"')
    w('b = "asteroid"')
    w('response = "ignore"')
    if args.firing:
        w("")
        w("[[collide]]")
        w('a = "bullet"')
        w('b = "asteroid"')
        w('response = "destroy"')
        w("")
        w("[[collide]]")
        w('a = "ship"')
        w('b = "asteroid"')
        w('response = "report"')
        w("")
        w("[templates.bullet]")
        w('layer = "bullet"')
        w('shape = { kind = "circle", radius = 0.2 }')
        w("mass = 0.05")
        w("lifetime = 60")
        w("")
        w("[[bodies]]")
        w('name = "ship"')
        w('layer = "ship"')
        w('shape = { kind = "polygon", vertices = [[1.0, 0.0], [-0.7, 0.6], [-0.7, -0.6]] }')
        w(f"position = [{num(SIDE / 2)}, {num(SIDE / 2)}]")
        w('controller = { kind = "ship", thrust = 12, turn_rate = 3, bullet = "bullet", '
          'bullet_speed = 30, muzzle = 1.5 }')
    for k in range(args.n):
        radius = rng.uniform(0.5, 3.0)
        if k % 2 == 0:
            shape = f'{{ kind = "circle", radius = {num(radius)} }}'
        else:
            sides = rng.randint(5, 8)
            verts = ", ".join(f"[{num(x)}, {num(y)}]" for x, y in polygon(rng, sides, radius))
            shape = f'{{ kind = "polygon", vertices = [{verts}] }}'
        px, py = rng.uniform(0.0, SIDE), rng.uniform(0.0, SIDE)
        if px >= SIDE:  # uniform may return the upper end; bounds are min <= p < max
            px = 0.0
        if py >= SIDE:
            py = 0.0
        angle = rng.uniform(0.0, 2.0 * math.pi)
        speed = rng.uniform(0.5, 5.0)
        heading = rng.uniform(0.0, 2.0 * math.pi)
        vx, vy = math.cos(heading) * speed, math.sin(heading) * speed
        if k == args.nudge:
            vx = math.nextafter(vx, math.inf)
        spin = rng.uniform(-1.0, 1.0)
        w("")
        w("[[bodies]]")
        w(f'name = "a{k}"')
        w('layer = "asteroid"')
        w(f"shape = {shape}")
        w(f"position = [{num(px)}, {num(py)}]")
        w(f"angle = {num(angle)}")
        w(f"velocity = [{num(vx)}, {num(vy)}]")
        w(f"angular_velocity = {num(spin)}")
    sys.stdout.write("\n".join(out) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
