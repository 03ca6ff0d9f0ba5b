"""Runs the items of `ricochet test` and `ricochet sweep` on a Dask distributed cluster.

`ricochet test --cluster tcp://HOST:PORT` (or `ricochet sweep … --cluster …`) starts
`python3 -m ricochet_dask`, writes one JSON line per item on its stdin (`{"argv": [...]}`:
the arguments of one `ricochet test --item` or `ricochet sweep … --item` process) and reads
one JSON line per item from its stdout, in the order they finish, after a first line
`{"connected": ADDRESS}` once the scheduler has answered (within `--timeout`, 10 s; Ricochet
stops a package that has said nothing 30 s after it started):

- `{"index": I, "worker": ADDRESS, "result": RESULT}`: RESULT is the item's own result line
  (docs/suites.md), ADDRESS the worker that ran it;
- with `--verify`, a sampled item's line also has `"verified": {"worker": OTHER, "result":
  RESULT2}`: the same item re-run on another worker. Ricochet compares the digests. When
  the re-run has no result (its worker left and no other is left, or `--verify-timeout`
  passed) it is `"verified": {"worker": OTHER, "error": WHY}`;
- `{"index": I, "error": WHY}`: the item never produced a result (its retries were spent,
  or the workers that held it died more often than the scheduler allows).

This package only moves work: it never judges a result, orders the output or sets the exit
code. That merge is Ricochet's (`src/suite/cluster.rs`). The scheduler and the workers are
the user's; a worker needs `distributed` and the same `ricochet` binary at the same absolute
path (or at `RICOCHET_EXE` in the worker's environment), with the scenarios and goldens at
the same paths (one machine, or a shared filesystem). With `--fetch-logs` a `test` item's
log comes back as bytes and is written into its `--out` folder here. The task code is
shipped to the workers by value, so they don't need this package installed.
"""

__version__ = "0.1.0"
