"""`python3 -m ricochet_dask`: maps `ricochet test` and `ricochet sweep` items over a Dask
cluster.

The protocol (stdin and stdout JSON lines) is in the package's docstring. Exit codes:
0 every item has its line, 2 bad input, 3 `distributed` is not installed, 4 the scheduler
can't be reached, 5 `--verify` with fewer than 2 workers, 6 nothing at the address answered
as a scheduler within `--timeout` seconds (a port that accepts and stays silent), 7 what
answered is not a Dask scheduler (its bytes don't read as Dask's protocol).
"""

import argparse
import base64
import json
import os
import sys
import threading
import time
import uuid

from ricochet_dask import task, verify

INSTALL = "install it with `pip install ./python` from Ricochet's repository"


def emit(obj):
    """One output line, flushed at once so Ricochet can show progress."""
    sys.stdout.write(json.dumps(obj, separators=(",", ":")) + "\n")
    sys.stdout.flush()


def parse_args(argv):
    p = argparse.ArgumentParser(prog="python3 -m ricochet_dask", description=__doc__)
    p.add_argument("--scheduler", required=True, help="tcp://HOST:PORT of the scheduler")
    p.add_argument("--exe", required=True, help="absolute path of the ricochet binary")
    p.add_argument("--cwd", required=True, help="folder the items' paths are relative to")
    p.add_argument("--retries", type=int, default=2, help="Dask retries of a crashed item")
    p.add_argument("--verify", action="store_true", help="re-run a sample on other workers")
    p.add_argument(
        "--verify-timeout",
        type=float,
        default=600.0,
        help="seconds a re-run may take on its worker before the item fails",
    )
    p.add_argument(
        "--fetch-logs",
        action="store_true",
        help="copy each fresh log's bytes back into the item's --out folder",
    )
    p.add_argument("--timeout", type=float, default=10.0, help="seconds to connect")
    return p.parse_args(argv)


def read_items(stream):
    items = []
    for n, line in enumerate(stream, 1):
        if not line.strip():
            continue
        obj = json.loads(line)
        argv = obj.get("argv")
        if not isinstance(argv, list) or not all(isinstance(a, str) for a in argv):
            raise ValueError(f"stdin line {n}: expected {{\"argv\": [strings]}}")
        items.append(argv)
    return items


def main(argv=None):
    args = parse_args(argv)
    if not os.path.isabs(args.exe):
        print(f"error: --exe {args.exe}: not an absolute path", file=sys.stderr)
        return 2
    try:
        items = read_items(sys.stdin)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    try:
        import cloudpickle
        from distributed import Client, as_completed
    except ImportError as e:
        print(f"error: Dask distributed is not installed ({e}): {INSTALL}", file=sys.stderr)
        return 3
    # The task goes to the workers by value: they need `distributed`, not this package.
    cloudpickle.register_pickle_by_value(task)
    client = connect(Client, args)
    if isinstance(client, int):
        return client
    # Ricochet waits a bounded time for this line: the sign that a scheduler answered.
    emit({"connected": args.scheduler})
    with client:
        return run(client, as_completed, items, args)


def connect(Client, args):
    """The client of the scheduler at `args.scheduler`, or the exit code when there is none.

    `Client(timeout=…)` bounds the TCP connect but not Dask's handshake after it: a port that
    accepts and never speaks would hold it forever. So the whole connect is also under a
    wall-clock deadline of `args.timeout` seconds, which ends the process (exit 6) from a
    timer thread, since the client's own thread can't be interrupted.
    """
    lock = threading.Lock()
    connected = False

    def expire():
        with lock:
            if connected:
                return
            print(
                f"error: no Dask scheduler answered at {args.scheduler} within "
                f"{args.timeout:g} s",
                file=sys.stderr,
                flush=True,
            )
            os._exit(6)

    timer = threading.Timer(args.timeout, expire)
    timer.daemon = True
    timer.start()
    try:
        client = Client(args.scheduler, timeout=args.timeout)
    except (OSError, TimeoutError) as e:
        print(f"error: cannot reach the Dask scheduler at {args.scheduler}: {e}", file=sys.stderr)
        return 4
    except Exception as e:  # noqa: BLE001 (bytes that are not Dask's: any error of the reader)
        detail = f"{type(e).__name__}: {e}" if str(e) else type(e).__name__
        print(
            f"error: {args.scheduler} is not a Dask scheduler: its answer does not read as "
            f"Dask's protocol ({detail})",
            file=sys.stderr,
        )
        return 7
    finally:
        with lock:
            connected = True
        timer.cancel()
    return client


# How often the loop looks for finished items; the scheduler is asked for its workers at
# most every WORKERS_EVERY seconds, and only while a verification re-run is out.
POLL = 0.05
WORKERS_EVERY = 0.5


class Rerun:
    """A verification re-run pinned to one worker: the first run's line, where it runs
    now, and when it was handed to that worker (time.monotonic())."""

    def __init__(self, i, line, worker, started, attempt):
        self.i = i
        self.line = line
        self.worker = worker
        self.started = started
        self.attempt = attempt


def write_log(cwd, argv, line, log_bytes):
    """`--fetch-logs`: the log's bytes into the item's own `--out` folder (as this machine
    sees it), and the result's `log` pointed there."""
    out = argv[argv.index("--out") + 1] if "--out" in argv[:-1] else None
    log = line["result"].get("log")
    if out is None or not log:
        return
    path = os.path.join(out, os.path.basename(log))
    full = os.path.join(cwd, path)
    os.makedirs(os.path.dirname(full) or ".", exist_ok=True)
    # Through a temporary file renamed into place, like every file Ricochet writes.
    tmp = f"{full}.part-{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(base64.b64decode(log_bytes))
    os.replace(tmp, full)
    line["result"]["log"] = path


def run(client, as_completed, items, args):
    workers = client.scheduler_info()["workers"]
    if args.verify and len(workers) < 2:
        print(
            f"error: --verify re-runs items on another worker, and the cluster at "
            f"{args.scheduler} has {len(workers)}",
            file=sys.stderr,
        )
        return 5
    run_id = uuid.uuid4().hex[:8]
    index = {}
    for i, argv in enumerate(items):
        fut = client.submit(
            task.run_item,
            args.exe,
            args.cwd,
            argv,
            False,
            args.fetch_logs,
            key=f"ricochet-item-{run_id}-{i}",
            retries=args.retries,
        )
        index[fut] = i
    checked = set(verify.sample(len(items))) if args.verify else set()
    done = as_completed(list(index))
    reruns = {}

    def pin(i, line, worker, attempt):
        again = client.submit(
            task.run_item,
            args.exe,
            args.cwd,
            items[i],
            True,
            False,
            key=f"ricochet-verify-{run_id}-{i}-{attempt}",
            workers=[worker],
            allow_other_workers=False,
            retries=args.retries,
        )
        reruns[again] = Rerun(i, line, worker, time.monotonic(), attempt)

    asked = 0.0
    live = list(workers)
    while not done.is_empty() or reruns:
        moved = False
        for fut in done.next_batch(block=False):
            moved = True
            i = index[fut]
            try:
                r = fut.result()
                line = {"index": i, "worker": r["worker"], "result": json.loads(r["line"])}
            except Exception as e:  # noqa: BLE001 (any failure of the task is reported)
                emit({"index": i, "error": f"{type(e).__name__}: {e}"})
                continue
            if r.get("log_bytes"):
                write_log(args.cwd, items[i], line, r["log_bytes"])
            if i not in checked:
                emit(line)
                continue
            live = list(client.scheduler_info()["workers"])
            other = verify.other_worker(live, r["worker"])
            if other is None:
                line["verified"] = {"error": f"no worker other than {r['worker']} is left"}
                emit(line)
                continue
            pin(i, line, other, 0)
        if reruns and time.monotonic() - asked >= WORKERS_EVERY:
            asked = time.monotonic()
            live = list(client.scheduler_info()["workers"])
        for fut, rerun in list(reruns.items()):
            line = rerun.line
            if fut.done():
                moved = True
                del reruns[fut]
                try:
                    again = fut.result()
                    line["verified"] = {
                        "worker": again["worker"],
                        "result": json.loads(again["line"]),
                    }
                except Exception as e:  # noqa: BLE001
                    line["verified"] = {"worker": rerun.worker, "error": f"{type(e).__name__}: {e}"}
                emit(line)
                continue
            action, detail = verify.rerun_state(
                line["worker"],
                rerun.worker,
                live,
                time.monotonic() - rerun.started,
                args.verify_timeout,
            )
            if action == "wait":
                continue
            moved = True
            del reruns[fut]
            fut.cancel()
            if action == "move":
                pin(rerun.i, line, detail, rerun.attempt + 1)
            else:
                line["verified"] = {"worker": rerun.worker, "error": detail}
                emit(line)
        if not moved:
            time.sleep(POLL)
    return 0
