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


def scratch_argv(argv, out_dir, bless=False):
    """`argv` with its log's `--out` folder (if it has one) moved to `out_dir`: for a
    verification re-run, so the first run's kept log is not replaced, and without `--bless`
    (the goldens are the first run's to write) unless `bless`; for `--fetch-logs`, so the
    log is read from this worker's own scratch folder and sent back."""
    rerun = []
    skip = False
    for i, arg in enumerate(argv):
        if skip:
            skip = False
            continue
        if arg == "--bless" and not bless:
            continue
        if arg == "--out" and i + 1 < len(argv):
            rerun += ["--out", out_dir]
            skip = True
            continue
        rerun.append(arg)
    return rerun


# The worker's own `ricochet`, when it is not at the path of the caller's (a node where the
# binary is installed elsewhere). `--verify` catches one that computes differently.
EXE_VAR = "RICOCHET_EXE"


def run_item(exe, cwd, argv, scratch=False, fetch_log=False):
    """Runs `exe argv` in `cwd` on this worker (`exe`: `RICOCHET_EXE` if the worker's
    environment sets it) and returns
    `{"worker": ADDRESS, "line": RESULT_LINE, "log_bytes": BASE64 or None}`.

    `scratch`: a verification re-run (see `scratch_argv`). `fetch_log`: the log goes to a
    scratch folder of this worker and its bytes come back, for callers that can't read the
    worker's `--out` folder.
    """
    import json

    from distributed import get_worker

    exe = os.environ.get(EXE_VAR) or exe
    # Test only (scripts/cluster-ci.sh): makes items slow enough to kill a worker mid-run.
    delay = os.environ.get("RICOCHET_DASK_TEST_DELAY")
    if delay:
        time.sleep(float(delay))
    log_bytes = None
    with tempfile.TemporaryDirectory(prefix="ricochet-item-") as tmp:
        if scratch:
            args = scratch_argv(argv, tmp)
        elif fetch_log:
            args = scratch_argv(argv, tmp, bless=True)
        else:
            args = list(argv)
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
        if fetch_log and not scratch:
            path = json.loads(line).get("log")
            if path:
                with open(os.path.join(cwd, path), "rb") as f:
                    log_bytes = base64.b64encode(f.read()).decode("ascii")
    return {"worker": get_worker().address, "line": line, "log_bytes": log_bytes}
