"""What a worker runs: one `ricochet test --item` process.

This module is pickled by value to the workers, so it may import only the standard library
and `distributed`.
"""

import base64
import os
import subprocess
import tempfile
import time


class ItemCrashed(RuntimeError):
    """The item's process ended without a result line (killed, out of memory, a crash).

    Raised so that Dask's `retries=` runs the item again; a verdict, even `error`, is a
    result and is never retried.
    """


def result_line(stdout: str):
    """The last non-empty line of an item process's stdout, or None."""
    for line in reversed(stdout.splitlines()):
        if line.strip():
            return line
    return None


def scratch_argv(argv, out_dir):
    """`argv` for a verification re-run: without `--bless` (the goldens are the first run's
    to write) and with its log in `out_dir`, so the first run's kept log is not replaced."""
    rerun = []
    skip = False
    for i, arg in enumerate(argv):
        if skip:
            skip = False
            continue
        if arg == "--bless":
            continue
        if arg == "--out" and i + 1 < len(argv):
            skip = True
            continue
        rerun.append(arg)
    return rerun + ["--out", out_dir]


def run_item(exe, cwd, argv, scratch=False, fetch_log=False):
    """Runs `exe argv` in `cwd` on this worker and returns
    `{"worker": ADDRESS, "line": RESULT_LINE, "log_bytes": BASE64 or None}`.

    `scratch`: a verification re-run (see `scratch_argv`). `fetch_log`: also return the
    fresh log's bytes, for workers whose `--out` folder the caller can't read.
    """
    from distributed import get_worker

    # Test only (scripts/cluster-ci.sh): makes items slow enough to kill a worker mid-run.
    delay = os.environ.get("RICOCHET_DASK_TEST_DELAY")
    if delay:
        time.sleep(float(delay))
    with tempfile.TemporaryDirectory(prefix="ricochet-verify-") as tmp:
        args = scratch_argv(argv, tmp) if scratch else list(argv)
        proc = subprocess.run(
            [exe, *args],
            cwd=cwd,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            check=False,
        )
    stdout = proc.stdout.decode("utf-8", errors="replace")
    line = result_line(stdout)
    if proc.returncode < 0 or line is None:
        stderr = proc.stderr.decode("utf-8", errors="replace").strip()
        raise ItemCrashed(
            f"{exe} {' '.join(args)}: exit status {proc.returncode}, no result line; "
            f"{stderr[-500:]}"
        )
    log_bytes = None
    if fetch_log and not scratch:
        import json

        path = json.loads(line).get("log")
        if path:
            with open(os.path.join(cwd, path), "rb") as f:
                log_bytes = base64.b64encode(f.read()).decode("ascii")
    return {"worker": get_worker().address, "line": line, "log_bytes": log_bytes}
