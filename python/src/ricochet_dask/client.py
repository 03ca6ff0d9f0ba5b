"""`python3 -m ricochet_dask`: maps `ricochet test` items over a Dask cluster.

The protocol (stdin and stdout JSON lines) is in the package's docstring. Exit codes:
0 every item has its line, 2 bad input, 3 `distributed` is not installed, 4 the scheduler
can't be reached, 5 `--verify` with fewer than 2 workers.
"""

import argparse
import base64
import json
import os
import sys
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
    p.add_argument("--fetch-logs", action="store_true", help="copy fresh logs back")
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
    try:
        client = Client(args.scheduler, timeout=args.timeout)
    except (OSError, TimeoutError) as e:
        print(f"error: cannot reach the Dask scheduler at {args.scheduler}: {e}", file=sys.stderr)
        return 4
    with client:
        return run(client, as_completed, items, args)


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
    rerun_of = {}
    firsts = {}
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
    for fut in done:
        if fut in rerun_of:
            i = rerun_of[fut]
            first = firsts.pop(i)
            try:
                again = fut.result()
                first["verified"] = {"worker": again["worker"], "result": json.loads(again["line"])}
            except Exception as e:  # noqa: BLE001 (any failure of the task is reported)
                first["verified"] = {"error": f"{type(e).__name__}: {e}"}
            emit(first)
            continue
        i = index[fut]
        try:
            r = fut.result()
            line = {"index": i, "worker": r["worker"], "result": json.loads(r["line"])}
        except Exception as e:  # noqa: BLE001
            emit({"index": i, "error": f"{type(e).__name__}: {e}"})
            continue
        if r.get("log_bytes") and line["result"].get("log"):
            path = os.path.join(args.cwd, line["result"]["log"])
            os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
            with open(path, "wb") as f:
                f.write(base64.b64decode(r["log_bytes"]))
        if i not in checked:
            emit(line)
            continue
        other = verify.other_worker(client.scheduler_info()["workers"], r["worker"])
        if other is None:
            line["verified"] = {"error": f"no worker other than {r['worker']} is left"}
            emit(line)
            continue
        again = client.submit(
            task.run_item,
            args.exe,
            args.cwd,
            items[i],
            True,
            False,
            key=f"ricochet-verify-{run_id}-{i}",
            workers=[other],
            allow_other_workers=False,
            retries=args.retries,
        )
        rerun_of[again] = i
        firsts[i] = line
        done.add(again)
    return 0
