"""Unit tests of the package's pure parts (python3 -m unittest discover python/tests)."""

import argparse
import contextlib
import io
import json
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ricochet_dask import client, task, verify  # noqa: E402


class Sample(unittest.TestCase):
    def test_one_in_ten_spread_evenly(self):
        # ceil(25 / 10) = 3 picks at 25*k//3 for k = 0, 1, 2.
        self.assertEqual(verify.sample(25), [0, 8, 16])

    def test_at_least_one(self):
        self.assertEqual(verify.sample(1), [0])
        self.assertEqual(verify.sample(6), [0])

    def test_every_item_when_share_is_one(self):
        self.assertEqual(verify.sample(4, share=1), [0, 1, 2, 3])

    def test_empty(self):
        self.assertEqual(verify.sample(0), [])


class OtherWorker(unittest.TestCase):
    def test_next_in_sorted_order_wrapping(self):
        ws = ["tcp://127.0.0.1:3", "tcp://127.0.0.1:1", "tcp://127.0.0.1:2"]
        self.assertEqual(verify.other_worker(ws, "tcp://127.0.0.1:1"), "tcp://127.0.0.1:2")
        self.assertEqual(verify.other_worker(ws, "tcp://127.0.0.1:3"), "tcp://127.0.0.1:1")

    def test_none_when_alone(self):
        self.assertIsNone(verify.other_worker(["tcp://a:1"], "tcp://a:1"))


class ScratchArgv(unittest.TestCase):
    def test_drops_bless_and_moves_the_log(self):
        argv = ["test", "--item", "s/a.toml", "--out", "/tmp/logs", "--bless"]
        self.assertEqual(
            task.scratch_argv(argv, "/scratch"),
            ["test", "--item", "s/a.toml", "--out", "/scratch"],
        )

    def test_fetching_a_log_keeps_bless(self):
        argv = ["test", "--item", "s/a.toml", "--out", "/tmp/logs", "--bless"]
        self.assertEqual(
            task.scratch_argv(argv, "/scratch", bless=True),
            ["test", "--item", "s/a.toml", "--out", "/scratch", "--bless"],
        )

    def test_a_sweep_item_has_no_log_to_move(self):
        argv = ["sweep", "a.toml", "--set", "world.dt=1/30", "--item", "0"]
        self.assertEqual(task.scratch_argv(argv, "/scratch"), argv)

    def test_result_line_is_the_last_non_empty(self):
        self.assertEqual(task.result_line('noise\n{"a":1}\n\n'), '{"a":1}')
        self.assertIsNone(task.result_line("\n \n"))


class WriteLog(unittest.TestCase):
    """`--fetch-logs`: the bytes land in the item's own --out folder, relative to --cwd."""

    def test_the_bytes_go_to_the_out_folder_and_the_line_says_so(self):
        import base64
        import tempfile

        with tempfile.TemporaryDirectory() as cwd:
            argv = ["test", "--item", "s/a.toml", "--out", "kept"]
            line = {"index": 0, "result": {"log": "/worker/scratch/a.mcap"}}
            client.write_log(cwd, argv, line, base64.b64encode(b"MCAP bytes").decode())
            self.assertEqual(Path(cwd, "kept", "a.mcap").read_bytes(), b"MCAP bytes")
            self.assertEqual(line["result"]["log"], "kept/a.mcap")
            self.assertEqual(sorted(p.name for p in Path(cwd, "kept").iterdir()), ["a.mcap"])


class RerunState(unittest.TestCase):
    def test_waits_while_its_worker_is_there(self):
        self.assertEqual(verify.rerun_state("A", "B", ["A", "B"], 1.0, 10.0), ("wait", None))

    def test_moves_when_its_worker_left(self):
        self.assertEqual(verify.rerun_state("A", "B", ["A", "C"], 1.0, 10.0), ("move", "C"))

    def test_fails_named_when_only_the_first_worker_is_left(self):
        action, why = verify.rerun_state("A", "B", ["A"], 1.0, 10.0)
        self.assertEqual(action, "fail")
        self.assertEqual(why, "B left the cluster and no worker other than A is left")

    def test_fails_named_after_the_timeout(self):
        action, why = verify.rerun_state("A", "B", ["A", "B"], 10.5, 10.0)
        self.assertEqual(action, "fail")
        self.assertEqual(why, "no result from B in 10 s (--verify-timeout)")


class FakeFuture:
    def __init__(self, value=None):
        self.value = value
        self.cancelled = False

    def done(self):
        return self.value is not None

    def result(self):
        return self.value

    def cancel(self):
        self.cancelled = True


class FakeAsCompleted:
    """Dask's as_completed over futures that are already done."""

    def __init__(self, futures):
        self.futures = list(futures)

    def is_empty(self):
        return not self.futures

    def next_batch(self, block=True):
        batch, self.futures = self.futures, []
        return batch


class FakeClient:
    """A cluster whose first runs finish on `first`, and whose pinned re-runs finish only
    on the workers in `answering`; `leave` is removed from the workers once a re-run has
    been pinned to it."""

    def __init__(self, workers, first, answering, leave=None):
        self.workers = list(workers)
        self.first = first
        self.answering = answering
        self.leave = leave
        self.pinned = []
        self.asked = 0

    def scheduler_info(self):
        # The loop asks about every POLL (0.05 s) while a re-run is out: 100 asks is 5 s,
        # far past these tests' timeouts. A loop that waits forever fails here instead.
        self.asked += 1
        if self.asked > 100:
            raise AssertionError("the re-run is still waited for after 5 s")
        return {"workers": {w: {} for w in self.workers}}

    def submit(self, fn, exe, cwd, argv, scratch, fetch, key, retries, workers=None,
               allow_other_workers=True):
        line = json.dumps({"digest": "00aa"})
        if workers is None:
            return FakeFuture({"worker": self.first, "line": line, "log_bytes": None})
        (w,) = workers
        self.pinned.append(w)
        if w == self.leave and w in self.workers:
            self.workers.remove(w)
        if w in self.answering:
            return FakeFuture({"worker": w, "line": line, "log_bytes": None})
        return FakeFuture()


def run_one(fake, timeout):
    args = argparse.Namespace(
        exe="/bin/ricochet", cwd="/", retries=0, verify=True, verify_timeout=timeout,
        fetch_logs=False, scheduler="tcp://s:1",
    )
    out = io.StringIO()
    saved = client.WORKERS_EVERY
    client.WORKERS_EVERY = 0.0
    try:
        with contextlib.redirect_stdout(out):
            code = client.run(fake, FakeAsCompleted, [["test", "--item", "a.toml"]], args)
    finally:
        client.WORKERS_EVERY = saved
    return code, [json.loads(line) for line in out.getvalue().splitlines()]


class PinnedRerun(unittest.TestCase):
    """A verification re-run pinned to a worker never waits forever (issue #23)."""

    def test_a_re_run_whose_worker_left_moves_to_another(self):
        fake = FakeClient(["A", "B", "C"], first="A", answering={"C"}, leave="B")
        code, lines = run_one(fake, timeout=30.0)
        self.assertEqual(code, 0)
        self.assertEqual(fake.pinned, ["B", "C"])
        self.assertEqual(lines, [{
            "index": 0, "worker": "A", "result": {"digest": "00aa"},
            "verified": {"worker": "C", "result": {"digest": "00aa"}},
        }])

    def test_a_re_run_that_never_answers_fails_after_the_timeout(self):
        fake = FakeClient(["A", "B"], first="A", answering=set())
        code, lines = run_one(fake, timeout=0.2)
        self.assertEqual(code, 0)
        self.assertEqual(lines[0]["verified"], {
            "worker": "B", "error": "no result from B in 0.2 s (--verify-timeout)",
        })

class Connect(unittest.TestCase):
    """`client.connect`'s exit codes, with a stand-in for `distributed.Client`."""

    args = argparse.Namespace(scheduler="tcp://127.0.0.1:1", timeout=5.0)

    def connect(self, error):
        def Client(*_args, **_kwargs):  # noqa: N802 (stands in for the class)
            raise error

        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            code = client.connect(Client, self.args)
        return code, err.getvalue()

    def test_an_answer_that_is_not_dask_is_named(self):
        # What distributed raises on a length read from HTTP's bytes.
        code, err = self.connect(MemoryError())
        self.assertEqual(code, 7)
        self.assertIn("tcp://127.0.0.1:1 is not a Dask scheduler", err)
        self.assertIn("(MemoryError)", err)

    def test_a_refused_connection_is_unreachable(self):
        code, err = self.connect(ConnectionRefusedError("refused"))
        self.assertEqual(code, 4)
        self.assertIn("cannot reach the Dask scheduler", err)

    def test_a_client_is_returned_and_the_deadline_cancelled(self):
        sentinel = object()
        self.assertIs(client.connect(lambda *a, **k: sentinel, self.args), sentinel)


if __name__ == "__main__":
    unittest.main()
