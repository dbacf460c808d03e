"""bench/windows.py: a window's figures are the difference of two cumulative `stats` replies, and
the modes and the control are compared on the right windows."""

import unittest

import windows as win


def figures(cycles, missed, latency):
    return {"pid": {"cycles": cycles, "missed": missed, "latency": dict(latency)}}


def window(kind, latency):
    """A window whose one task ran a cycle for each (bound, count) of `latency`."""
    return {"kind": kind, "tasks": {"pid": {"cycles": sum(n for _, n in latency), "missed": 0,
                                            "latency_histogram": sorted(latency)}}}


class Between(unittest.TestCase):
    def test_counts_only_what_happened_within_the_window(self):
        before = figures(100, 2, {1000: 90, 2000: 10})
        after = figures(150, 3, {1000: 130, 2000: 10, 4000: 10})
        got = win.between(before, after)["pid"]
        self.assertEqual(got["cycles"], 50)
        self.assertEqual(got["missed"], 1)
        # 2000's bucket did not move: it is left out, not counted as 0 or as 10
        self.assertEqual(got["latency_histogram"], [(1000, 40), (4000, 10)])


class P99(unittest.TestCase):
    def test_is_the_bucket_that_holds_the_99th_percentile(self):
        self.assertEqual(win.p99([(1000, 98), (2000, 1), (8000, 1)]), 2000)
        self.assertEqual(win.p99([(1000, 98), (8000, 2)]), 8000)
        self.assertEqual(win.p99([]), 0)


class Compare(unittest.TestCase):
    def test_ratio_is_loaded_over_quiet_and_control_splits_quiet_windows_by_pair(self):
        # pairs: (quiet, loaded), (loaded, quiet), (quiet, loaded), (loaded, quiet)
        fast, slow = [(1000, 100)], [(3000, 100)]
        ws = [window("none", fast), window("x", slow),
              window("x", slow), window("none", [(2000, 100)]),
              window("none", fast), window("x", slow),
              window("x", slow), window("none", [(2000, 100)])]
        c = win.compare(ws, ["pid"], "none", "x")
        # the quiet windows together: half at 1000, half at 2000, so their p99 is 2000
        self.assertEqual(c["p99_ns"]["none"]["pid"], 2000)
        self.assertEqual(c["p99_ns"]["x"]["pid"], 3000)
        self.assertAlmostEqual(c["ratios"]["pid"], 1.5)
        # even pairs' quiet windows are at 1000, odd pairs' at 2000
        self.assertAlmostEqual(c["control_ratios"]["pid"], 2.0)
        self.assertAlmostEqual(c["control_worst"], 2.0)
        self.assertEqual(c["cycles_and_missed"]["x"]["pid"], {"cycles": 400, "missed": 0})
        self.assertEqual([w["kind"] for w in c["windows"]], [w["kind"] for w in ws])

    def test_control_worst_is_the_one_farthest_from_one_either_way(self):
        def pair_of_tasks(kind, a, b):
            return {"kind": kind, "tasks": {"a": window(kind, a)["tasks"]["pid"], "b": window(kind, b)["tasks"]["pid"]}}
        one, two, four = [(1000, 100)], [(2000, 100)], [(4000, 100)]
        # quiet windows: pair 0 (a 4000, b 1000), pair 1 (a 1000, b 2000): a 0.25x, b 2.0x
        ws = [pair_of_tasks("none", four, one), pair_of_tasks("x", one, one),
              pair_of_tasks("x", one, one), pair_of_tasks("none", one, two)]
        c = win.compare(ws, ["a", "b"], "none", "x")
        self.assertAlmostEqual(c["control_ratios"]["a"], 0.25)
        self.assertAlmostEqual(c["control_ratios"]["b"], 2.0)
        self.assertAlmostEqual(c["control_worst"], 0.25)


if __name__ == "__main__":
    unittest.main()
