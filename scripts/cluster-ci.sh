#!/usr/bin/env bash
# The cluster step of .ci/run (issue #23): `ricochet test --cluster` on a Dask scheduler and
# 2 workers on 127.0.0.1, started and stopped here by their PIDs. It checks that
#   1. the cluster run prints the same lines and keeps byte-identical logs as the local run
#      (with --verify: a sample re-run on the other worker, digests compared), and so does
#      --fetch-logs (the logs' bytes come back from the workers);
#   2. `ricochet sweep --cluster --verify` writes the same CSV and SVG bytes as the local
#      sweep;
#   3. with one worker SIGKILLed mid-run, every item of a generated suite still completes;
#   4. a worker whose `ricochet` reports another final state (a wrapper, RICOCHET_EXE) is
#      caught by --verify, in `test` and in `sweep`, and named (exit code 1).
# Loopback only, every wait bounded; about 60 s on 2 cores once the venv exists.
#
#   scripts/cluster-ci.sh [RICOCHET]   (default: target/debug/ricochet, built by the caller)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
ricochet=${1:-$root/target/debug/ricochet}
[ -x "$ricochet" ] || { echo "no ricochet binary at $ricochet: cargo build first" >&2; exit 1; }

# The package and its pinned dependencies (python/pyproject.toml, python/constraints.txt),
# in a venv reinstalled when either, or the package's code, changes.
venv="$root/target/cluster-venv"
pins=$(cat python/pyproject.toml python/constraints.txt python/src/ricochet_dask/*.py)
if [ "$(cat "$venv/pins.txt" 2>/dev/null || true)" != "$pins" ]; then
    rm -rf "$venv"
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --disable-pip-version-check -c python/constraints.txt ./python
    printf '%s' "$pins" >"$venv/pins.txt"
fi
timeout 120 "$venv/bin/python" -m unittest discover -s python/tests
export RICOCHET_PYTHON="$venv/bin/python"
# The ports that are not a scheduler (one silent, one speaking HTTP): named within 10 s, exit
# code 2 (tests/cluster_cli.rs, which skips them without distributed and here must not).
# The test binary is the one `cargo test` built before this step.
RICOCHET_REQUIRE_DASK=1 timeout 300 cargo test --locked --quiet --test integration cluster_cli::

work=$(mktemp -d)
pids=()
# Workers first, then the scheduler (a worker whose scheduler is gone keeps trying to
# reconnect); SIGTERM, and SIGKILL for any still there 10 s later.
stop_cluster() {
    local pid
    for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
    for _ in $(seq 1 100); do
        alive=0
        for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
        [ "$alive" -eq 0 ] && break
        sleep 0.1
    done
    for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
    for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
    rm -rf "$work"
}
trap stop_cluster EXIT
show_logs() { tail -n 20 "$work"/*.log >&2 || true; }

# Port 0: the scheduler picks a free port and writes its address to the scheduler file.
"$venv/bin/dask" scheduler --host 127.0.0.1 --port 0 --no-dashboard \
    --scheduler-file "$work/scheduler.json" >"$work/scheduler.log" 2>&1 &
pids+=($!)
for _ in $(seq 1 300); do [ -s "$work/scheduler.json" ] && break; sleep 0.1; done
[ -s "$work/scheduler.json" ] || { echo "the scheduler did not start in 30 s" >&2; show_logs; exit 1; }
address=$("$venv/bin/python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["address"])' \
    "$work/scheduler.json")
case "$address" in tcp://127.0.0.1:*) ;; *) echo "scheduler left loopback: $address" >&2; exit 1 ;; esac
# --no-nanny: the PID started is the worker itself, so SIGKILL ends the worker (a nanny
# would start a new one). RICOCHET_DASK_TEST_DELAY: each item sleeps 0.2 s first, so the
# kill below lands mid-run.
worker_pids=()
for n in 1 2; do
    RICOCHET_DASK_TEST_DELAY=0.2 "$venv/bin/dask" worker "$address" --no-nanny --nthreads 1 \
        --host 127.0.0.1 --no-dashboard --name "worker-$n" >"$work/worker-$n.log" 2>&1 &
    pids=($! "${pids[@]}")
    worker_pids+=($!)
done
timeout 60 "$venv/bin/python" -c \
    'import sys; from distributed import Client; Client(sys.argv[1], timeout=30).wait_for_workers(2, timeout=30)' \
    "$address" || { echo "2 workers did not join in 30 s" >&2; show_logs; exit 1; }
echo "cluster at $address: scheduler and 2 workers, PIDs ${pids[*]}"

# 1. The shipped scenarios, locally and on the cluster: the same lines, the same logs.
"$ricochet" test scenarios -j 2 --keep "$work/local" >"$work/local.txt"
timeout 120 "$ricochet" test scenarios --cluster "$address" --verify --keep "$work/cluster" \
    >"$work/cluster.txt" || { cat "$work/cluster.txt"; show_logs; exit 1; }
diff "$work/local.txt" "$work/cluster.txt" || { echo "cluster lines differ from local" >&2; exit 1; }
for log in "$work"/local/*.mcap; do
    cmp "$log" "$work/cluster/$(basename "$log")"
done
echo "cluster run: $(tail -n 1 "$work/cluster.txt"), the same lines and $(ls "$work"/local/*.mcap | wc -l) byte-identical logs as -j 2"
timeout 120 "$ricochet" test scenarios --cluster "$address" --keep "$work/fetched" --fetch-logs \
    >"$work/fetched.txt" || { cat "$work/fetched.txt"; show_logs; exit 1; }
diff "$work/local.txt" "$work/fetched.txt" || { echo "--fetch-logs lines differ" >&2; exit 1; }
for log in "$work"/local/*.mcap; do
    cmp "$log" "$work/fetched/$(basename "$log")"
done
echo "--fetch-logs: the same lines and byte-identical logs, copied back from the workers"

# 2. A sweep, locally and on the cluster (each combination and the reference one item):
# not timed (--repeat 0), so the CSV and SVG must be the same bytes.
sweep=(sweep scenarios/platformer.toml --set world.dt=1/30,1/60,1/120
    --set world.gravity.y=-20,-30 --repeat 0)
"$ricochet" "${sweep[@]}" --csv "$work/sweep-local.csv" >"$work/sweep-local.txt"
start=$(date +%s.%N)
timeout 120 "$ricochet" "${sweep[@]}" --csv "$work/sweep-cluster.csv" --cluster "$address" \
    --verify >"$work/sweep-cluster.txt" || { cat "$work/sweep-cluster.txt"; show_logs; exit 1; }
took=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$start" "$(date +%s.%N)")
cmp "$work/sweep-local.csv" "$work/sweep-cluster.csv"
cmp "$work/sweep-local.svg" "$work/sweep-cluster.svg"
diff <(head -n -1 "$work/sweep-local.txt") <(head -n -1 "$work/sweep-cluster.txt") \
    || { echo "the sweep's table differs on the cluster" >&2; exit 1; }
echo "sweep --cluster --verify: $(($(wc -l <"$work/sweep-local.csv") - 1)) rows in $took s, CSV and SVG byte-identical to the local sweep"

# 3. One worker SIGKILLed mid-run: its items are rerun on the other, every item completes.
python3 scripts/gen_suite.py 40 "$work/suite/scenarios" 2>/dev/null
"$ricochet" test "$work/suite/scenarios" --bless -j 2 >/dev/null
timeout 120 "$ricochet" test "$work/suite/scenarios" --cluster "$address" >"$work/killed.txt" &
run=$!
for _ in $(seq 1 300); do
    [ "$(wc -l <"$work/killed.txt")" -ge 4 ] && break
    sleep 0.05
done
done_at_kill=$(wc -l <"$work/killed.txt")
kill -KILL "${worker_pids[0]}"
status=0
wait "$run" || status=$?
[ "$done_at_kill" -lt 40 ] || { echo "the run ended before the kill" >&2; exit 1; }
[ "$status" -eq 0 ] && [ "$(tail -n 1 "$work/killed.txt")" = "40 passed, 0 failed" ] || {
    echo "after the kill: exit $status" >&2
    cat "$work/killed.txt"
    show_logs
    exit 1
}
echo "killed worker-1 (PID ${worker_pids[0]}) after $done_at_kill of 40 items: 40 passed, 0 failed"

# 4. A worker that computes differently: its `ricochet` (RICOCHET_EXE, read by the worker)
# is a wrapper that reports another final state. With worker-1 gone, the cluster is
# worker-2 and this one, so every re-run of --verify pairs the two: the check must fail,
# name this worker, and say which one the golden digest agrees with.
cat >"$work/other-ricochet" <<EOF
#!/bin/sh
"$ricochet" "\$@" | sed -E 's/"(hash|digest)":"[0-9a-f]{16}"/"\\1":"0000000000000000"/'
EOF
chmod +x "$work/other-ricochet"
RICOCHET_EXE="$work/other-ricochet" "$venv/bin/dask" worker "$address" --no-nanny --nthreads 1 \
    --host 127.0.0.1 --no-dashboard --name other >"$work/worker-other.log" 2>&1 &
pids=($! "${pids[@]}")
timeout 60 "$venv/bin/python" -c \
    'import sys; from distributed import Client; Client(sys.argv[1], timeout=30).wait_for_workers(2, timeout=30)' \
    "$address" || { echo "the other worker did not join in 30 s" >&2; show_logs; exit 1; }
worker_at() { sed -n 's/.*Start worker at: *\(tcp:[^ ]*\).*/\1/p' "$1" | head -n 1; }
other=$(worker_at "$work/worker-other.log")
good=$(worker_at "$work/worker-2.log")
[ -n "$other" ] && [ -n "$good" ] || { echo "no worker addresses in the logs" >&2; show_logs; exit 1; }
status=0
timeout 120 "$ricochet" test scenarios --cluster "$address" --verify >"$work/other.txt" || status=$?
caught=$(grep -F -e "--verify: the workers disagree" "$work/other.txt" || true)
case "$status:$caught" in
    1:*"$other computed frames"*"(the golden digest agrees with $good)"*) ;;
    *) echo "--verify did not catch the other worker $other (exit $status):" >&2
       cat "$work/other.txt" >&2; show_logs; exit 1 ;;
esac
echo "test --verify caught $other (exit 1): $caught"
status=0
timeout 120 "$ricochet" "${sweep[@]}" --csv "$work/sweep-other.csv" --cluster "$address" \
    --verify >/dev/null 2>"$work/sweep-other.txt" || status=$?
caught=$(grep -F -e "--verify: the workers disagree" "$work/sweep-other.txt" || true)
case "$status:$caught" in
    1:*"$other computed frames"*) ;;
    *) echo "sweep --verify did not catch the other worker $other (exit $status):" >&2
       cat "$work/sweep-other.txt" >&2; show_logs; exit 1 ;;
esac
[ ! -e "$work/sweep-other.csv" ] || { echo "sweep wrote its CSV despite --verify" >&2; exit 1; }
echo "sweep --verify caught $other (exit 1): $caught"
