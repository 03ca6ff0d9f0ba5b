"""Unit tests of the package's pure parts (python3 -m unittest discover python/tests)."""

import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from ricochet_dask import task, verify  # noqa: E402


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

    def test_result_line_is_the_last_non_empty(self):
        self.assertEqual(task.result_line('noise\n{"a":1}\n\n'), '{"a":1}')
        self.assertIsNone(task.result_line("\n \n"))


if __name__ == "__main__":
    unittest.main()
