#!/usr/bin/env bash
# The determinism gate (issue #25): the same checksums, frame for frame, on x86-64, aarch64
# and wasm32, and on aarch64 the same log bytes as recordings/.
#
#   bash scripts/determinism-gate.sh              # what .ci/run runs
#   bash scripts/determinism-gate.sh --self-test  # platform sin_cos: must FAIL
#
# 1. installs Debian's Rust with its std source, the aarch64 cross gcc, qemu-user and
#    wasi-libc (apt, once; skipped when present);
# 2. builds crates/portable (ricochet-portable: ricochet-sim + the built-in scenes) natively
#    with the workspace's toolchain, and with Debian's rustc and -Zbuild-std for
#    aarch64-unknown-linux-gnu (with the recorder: liblz4's C source through the cross gcc),
#    wasm32-wasip1 (no threads: ricochet-sim without `parallel`) and, for the browser
#    example, wasm32-unknown-unknown;
# 3. runs every shipped scenario, scenarios/stress/ and the built-in scenes natively, under
#    qemu-aarch64 and under Node's WASI, and the browser example's asteroids under Node;
# 4. compares every frame's checksum and digest (scripts/determinism_compare.py names the
#    first differing scene, frame and targets), the final digests with recordings/*.digest,
#    and the aarch64 logs with recordings/*.mcap byte for byte.
# Prints the seconds of each phase. Exit 0 when all agree, 1 on a difference, 2 on a setup
# failure.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

self_test=false
case "${1:-}" in
    "") ;;
    --self-test) self_test=true ;;
    *) echo "usage: $0 [--self-test]" >&2; exit 2 ;;
esac

phase_start=$SECONDS
phase() {
    printf '  (%d s)\n--- gate: %s\n' "$((SECONDS - phase_start))" "$*"
    phase_start=$SECONDS
}

printf -- '--- gate: packages'
packages=(rustc-web cargo-web rust-web-src rust-web-llvm lld-22 gcc-aarch64-linux-gnu
    libc6-dev-arm64-cross qemu-user wasi-libc)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
    sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    echo " installing ${missing[*]}"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
        "${missing[@]}" >/dev/null || { echo "apt-get install failed" >&2; exit 2; }
fi

features=()
$self_test && features=(--features self-test-std-sin)

phase "build x86-64 (the workspace's toolchain)"
cargo build --locked --quiet -p ricochet-portable --features parallel "${features[@]}"
native="$root/target/debug/ricochet-portable"

# Debian's rustc, not rustup's, and its std built from source for each target. Its own
# target directory: another compiler's artifacts never mix with the workspace's.
cross() (
    export PATH="/usr/bin:$PATH" RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1
    export CARGO_TARGET_DIR="$root/target/gate"
    export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
    export CC_aarch64_unknown_linux_gnu=aarch64-linux-gnu-gcc
    export AR_aarch64_unknown_linux_gnu=aarch64-linux-gnu-ar
    # Debian's wasi-libc, linked by hand (rustc's self-contained copy is not shipped).
    export CARGO_TARGET_WASM32_WASIP1_RUSTFLAGS="-C link-self-contained=no \
        -L native=/usr/lib/wasm32-wasi -C link-arg=/usr/lib/wasm32-wasi/crt1-command.o"
    /usr/bin/cargo build --locked --quiet "$@"
)
gate_target="$root/target/gate"

phase "build aarch64-unknown-linux-gnu (build-std, with the recorder)"
cross -Zbuild-std --target aarch64-unknown-linux-gnu -p ricochet-portable --features logs "${features[@]}"

phase "build wasm32-wasip1 (build-std, no threads)"
# wasm32 panics abort: its std needs panic_abort built too.
cross -Zbuild-std=std,panic_abort --target wasm32-wasip1 -p ricochet-portable "${features[@]}"

phase "build wasm32-unknown-unknown (build-std, the browser example)"
cross -Zbuild-std=std,panic_abort --target wasm32-unknown-unknown -p ricochet-portable --example browser_asteroids "${features[@]}"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
files=(scenarios/*.toml scenarios/stress/*.toml)

phase "run x86-64 (2 threads)"
# On 2 threads (the rayon pool): the wasm32 builds have no threads, so agreeing with them
# shows the pool changes no bit.
"$native" --threads 2 "${files[@]}" >"$work/x86-64.txt"

phase "run aarch64 (qemu-aarch64), writing the scenarios' logs"
mkdir "$work/logs"
qemu-aarch64 -L /usr/aarch64-linux-gnu "$gate_target/aarch64-unknown-linux-gnu/debug/ricochet-portable" \
    --logs "$work/logs" "${files[@]}" >"$work/aarch64.txt"

phase "run wasm32-wasip1 (Node's WASI)"
node --no-warnings scripts/wasi-run.mjs "$gate_target/wasm32-wasip1/debug/ricochet-portable.wasm" \
    "$root" "${files[@]/#//repo/}" >"$work/wasm32-wasip1.txt"

phase "run wasm32-unknown-unknown (Node, the browser example's exports)"
node scripts/browser-asteroids.mjs \
    "$gate_target/wasm32-unknown-unknown/debug/examples/browser_asteroids.wasm" 200 300 \
    >"$work/wasm32-browser.txt"

phase "compare"
verdict=0
python3 scripts/determinism_compare.py recordings x86-64 "$work/x86-64.txt" \
    aarch64 "$work/aarch64.txt" wasm32-wasip1 "$work/wasm32-wasip1.txt" \
    --partial wasm32-browser "$work/wasm32-browser.txt" || verdict=1
logs=0
for golden in recordings/*.mcap; do
    if ! cmp "$golden" "$work/logs/$(basename "$golden")"; then
        echo "determinism gate: the aarch64 log of $(basename "$golden" .mcap) differs from $golden"
        verdict=1
    fi
    logs=$((logs + 1))
done
echo "aarch64 logs: $logs compared with recordings/*.mcap"
phase "done"

if $self_test; then
    if [ "$verdict" -eq 0 ]; then
        echo "self-test: platform sin_cos (the ship's thrust, the shapes' poses) was NOT caught"
        exit 1
    fi
    echo "self-test: the gate caught platform sin (above), as it must"
    exit 0
fi
[ "$verdict" -eq 0 ] && echo "determinism gate: x86-64, aarch64 and wasm32 agree"
exit "$verdict"
