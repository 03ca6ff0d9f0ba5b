#!/usr/bin/env bash
# Instructions per frame of one bench scene, counted by valgrind's callgrind: repeatable for
# the same binary whatever else the machine does (wall clock on a shared VM varies by ±30%).
#
#   scripts/instructions-per-frame.sh STEP_SCENE_BINARY SCENE [FRAMES_A] [FRAMES_B]
#
# Runs the `step_scene` harness (crates/scenes/examples) twice, stepping FRAMES_A and FRAMES_B
# frames after frame 0 (defaults 20 and 60), and prints (B - A) / (FRAMES_B - FRAMES_A): the
# cost of one frame with the scene's setup and frame 0 cancelled out. Build the harness with
# `cargo build --release -p ricochet-scenes --example step_scene`.
set -euo pipefail
bin=${1:?usage: instructions-per-frame.sh STEP_SCENE SCENE [FRAMES_A] [FRAMES_B]}
scene=${2:?usage: instructions-per-frame.sh STEP_SCENE SCENE [FRAMES_A] [FRAMES_B]}
a=${3:-20}
b=${4:-60}
command -v valgrind >/dev/null || { echo "valgrind not found (apt install valgrind)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
count() {
    valgrind --tool=callgrind --callgrind-out-file="$work/out.$1" "$bin" "$scene" "$1" 1 \
        >/dev/null 2>"$work/err.$1" || { cat "$work/err.$1" >&2; exit 1; }
    sed -n 's/^summary: //p' "$work/out.$1"
}
ia=$(count "$a")
ib=$(count "$b")
echo "$scene: $(( (ib - ia) / (b - a) )) instructions a frame (frames $a..$b after frame 0)"
