"""`--verify`: which items are re-run, and where."""

# One item in ten is re-run, at least one: enough to catch a node that computes
# differently in any suite of some size, for a tenth more work.
SHARE = 10


def sample(count, share=SHARE):
    """The indices of the items to re-run, spread evenly over `0..count` and the same for
    the same `count` (so a failure reproduces): `ceil(count / share)` of them."""
    if count <= 0:
        return []
    picks = -(-count // share)
    return sorted({k * count // picks for k in range(picks)})


def other_worker(workers, first):
    """The worker a re-run goes to: the next address after `first` in sorted order
    (wrapping), never `first` itself; None when there is no other worker."""
    others = sorted(w for w in workers if w != first)
    if not others:
        return None
    later = [w for w in others if w > first]
    return later[0] if later else others[0]


def rerun_state(first, pinned, live, waited, timeout):
    """What to do with a re-run pinned to `pinned` that has not finished after `waited`
    seconds on it, the first run having been on `first` and `live` the workers now:

    - `("wait", None)`;
    - `("move", WORKER)`: `pinned` left the cluster (a pinned task would wait for it
      forever), so the re-run goes to WORKER, another live worker than `first`;
    - `("fail", WHY)`: it took longer than `timeout` seconds, or no worker but `first` is
      left; WHY names the worker.
    """
    if waited > timeout:
        return ("fail", f"no result from {pinned} in {timeout:g} s (--verify-timeout)")
    if pinned in live:
        return ("wait", None)
    other = other_worker(live, first)
    if other is None:
        return ("fail", f"{pinned} left the cluster and no worker other than {first} is left")
    return ("move", other)
