"""scripts/bvh-scorecard on synthetic results: the right best backends, ratios and verdicts."""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
COLUMNS = ["scene", "rayset", "backend", "threads", "rays", "mrays_s", "build_ms", "hit_rate", "agree_hit", "agree_prim",
           "prim_ties"]


def row(scene, rayset, backend, mrays, build=10.0, threads=1, agree_prim="1", ties="0"):
    return {"scene": scene, "rayset": rayset, "backend": backend, "threads": threads, "rays": 1000, "mrays_s": mrays,
            "build_ms": build, "hit_rate": 0.5, "agree_hit": 1.0, "agree_prim": agree_prim, "prim_ties": ties}


def spread(r, lo, hi):
    """The row with its median's min and max over the repetitions."""
    return {**r, "mrays_s_min": lo, "mrays_s_max": hi}


def build_spread(r, lo, hi):
    """The row with its build time's min and max over the timed builds."""
    return {**r, "build_ms_min": lo, "build_ms_max": hi}


class Scorecard(unittest.TestCase):
    def run_on(self, rows, *args, directory=None):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(directory or d, "r.csv")
            columns = COLUMNS + [c for c in ("mrays_s_min", "mrays_s_max", "build_ms_min", "build_ms_max")
                                 if any(c in r for r in rows)]
            with open(path, "w", newline="") as f:
                w = csv.DictWriter(f, fieldnames=columns)
                w.writeheader()
                w.writerows(rows)
            return subprocess.run([sys.executable, os.path.join(HERE, "bvh_scorecard.py"), path, *args],
                                  capture_output=True, text=True)

    def test_compares_our_best_with_embrees_best_and_says_which_targets_are_met(self):
        rows = []
        for rayset in ("primary", "diffuse", "shadow"):
            rows += [row("a", rayset, "embree", 10.0, build=100), row("a", rayset, "embree:high", 12.0, build=500),
                     row("a", rayset, "bvh8", 13.8, build=80), row("a", rayset, "bvh8:watertight", 11.0),
                     row("a", rayset, "reference", 99.0), row("a", rayset, "bvh8", 50.0, threads=2)]
        result = self.run_on(rows)
        self.assertEqual(result.returncode, 0, result.stderr)
        out = result.stdout
        # Against embree:high (the faster), not the 99 of the reference or the 2-thread row.
        self.assertIn("| a | primary | embree:high | 12.00 | bvh8 | 13.80 | 1.15 | 1.10 | 0.80 |", out)
        self.assertIn("| geometric mean ≥ 1.10 | 1.15 | **met** |", out)
        self.assertIn("| default build ≤ 1.0 × Embree medium | max 0.80 | **met** |", out)
        self.assertIn("| watertight ≥ 1.0 × Embree's default mode | min 1.10 | **met** |", out)

    def test_the_leaky_plain_boxes_combination_is_not_a_watertight_configuration(self):
        rows = []
        for rayset in ("primary", "diffuse", "shadow"):
            rows += [row("a", rayset, "embree", 10.0), row("a", rayset, "bvh8", 13.0),
                     row("a", rayset, "bvh8:watertight:plain_boxes", 12.0), row("a", rayset, "bvh8:watertight", 9.0)]
        out = self.run_on(rows, "--no-plot").stdout
        # 9 / 10, not the faster leaky 12 / 10.
        self.assertIn("| watertight ≥ 1.0 × Embree's default mode | min 0.90", out)

    def test_rows_with_more_threads_get_their_own_section_with_the_build_speed_up(self):
        rows = [row("a", "primary", "embree", 10.0, build=100), row("a", "primary", "bvh8", 9.0, build=120),
                row("a", "primary", "embree", 18.0, build=60, threads=2), row("a", "primary", "bvh8", 19.8, build=66,
                                                                                threads=2)]
        result = self.run_on(rows)
        self.assertEqual(result.returncode, 0, result.stderr)
        out = result.stdout
        self.assertIn("## With 2 threads", out)
        # 19.8 / 18 at 2 threads beside 0.90 at one; build 66 / 60; our build 120 -> 66 ms.
        self.assertIn("| a | primary | bvh8 | 1.10 | 0.90 | 1.10 | 1.82× |", out)
        self.assertIn("Default build with 2 threads / Embree medium with 2 threads: max 1.10 (**missed** ≤ 1.0; "
                      "1 of 1 scenes above 1.0).", out)
        self.assertIn("Our default build, 1 → 2 threads: 1.82–1.82× faster (**met**: faster on every scene).", out)
        # The single-thread table is unchanged by the 2-thread rows.
        self.assertIn("| a | primary | embree | 10.00 | bvh8 | 9.00 | 0.90 |", out)

    def test_a_slower_scene_misses_the_per_scene_target(self):
        rows = [row("a", "primary", "embree", 10.0), row("a", "primary", "bvh2", 9.0, agree_prim="0.99", ties="5")]
        out = self.run_on(rows).stdout
        self.assertIn("| our best ≥ 1.0 × Embree's best on every scene and ray set | min 0.90; 1 of 1 rows below 1.0 | "
                      "**missed** |", out)
        # 0.99 same triangle plus 5 ties among 500 rays both hit: 100 %.
        self.assertIn("| same triangle ≥ 99.9 % (ties agree), every backend of ours | min 100.00 % (bvh2, a primary) | "
                      "**met** |", out)

    def test_agreement_targets_hold_every_backend_of_ours_not_only_the_fastest(self):
        slow_and_wrong = row("a", "shadow", "bvh8:watertight", 8.0)
        slow_and_wrong["agree_hit"] = 0.9919
        rows = [row("a", "shadow", "embree", 10.0), row("a", "shadow", "bvh8", 11.0), slow_and_wrong,
                row("a", "diffuse", "embree", 10.0), row("a", "diffuse", "bvh8", 11.0),
                row("a", "diffuse", "bvh8:watertight", 8.0, agree_prim="0.99")]
        out = self.run_on(rows, "--no-plot").stdout
        # The table's columns are our best's (bvh8, in full agreement) ...
        self.assertIn("| a | shadow | embree | 10.00 | bvh8 | 11.00 | 1.10 |", out)
        # ... the targets every backend's: 99 % same triangle, no ties, among 500 rays both hit.
        self.assertIn("| hit/miss agreement ≥ 99.99 %, every backend of ours | min 99.190 % "
                      "(bvh8:watertight, a shadow) | **missed** |", out)
        self.assertIn("| same triangle ≥ 99.9 % (ties agree), every backend of ours | min 99.00 % "
                      "(bvh8:watertight, a diffuse) | **missed** |", out)

    def test_each_ratio_gets_its_range_over_the_repetitions_and_a_miss_says_whether_noise_covers_it(self):
        rows = [spread(row("a", "diffuse", "embree", 10.0), 9.0, 10.5),
                spread(row("a", "diffuse", "bvh8", 9.5), 9.0, 10.8),  # below, but reaches 10.8 / 9 = 1.20
                spread(row("b", "diffuse", "embree", 10.0), 9.9, 10.1),
                spread(row("b", "diffuse", "bvh8", 9.0), 8.9, 9.1),  # below even at its fastest: 9.1 / 9.9
                spread(row("c", "diffuse", "embree", 10.0), 9.9, 10.1),
                spread(row("c", "diffuse", "bvh8", 12.0), 11.0, 12.5)]
        out = self.run_on(rows, "--no-plot").stdout
        # 9.0 / 10.5 = 0.86 at worst, 10.8 / 9.0 = 1.20 at best.
        self.assertIn("| a | diffuse | embree | 10.00 | bvh8 | 9.50 | 0.95 (0.86–1.20) |", out)
        self.assertIn("| b | diffuse | embree | 10.00 | bvh8 | 9.00 | 0.90 (0.88–0.92) |", out)
        # The verdict is the median's; the shortfall says how much of it noise can explain.
        self.assertIn("| our best ≥ 1.0 × Embree's best on every scene and ray set | min 0.90; 2 of 3 rows below 1.0, "
                      "1 of them within their min–max | **missed** |", out)
        self.assertIn("A ratio's range in brackets", out)

    def test_says_how_noisy_the_run_was_from_embrees_own_spread_over_the_repetitions(self):
        rows = []
        for scene, wide in (("a", False), ("b", False), ("c", True)):
            for rayset in ("primary", "diffuse", "shadow"):
                spread_hi = 13.0 if wide and rayset == "diffuse" else 10.2
                rows += [spread(row(scene, rayset, "embree", 10.0), 9.9, spread_hi),
                         spread(row(scene, rayset, "bvh8", 11.0), 10.9, 11.1),
                         spread(row(scene, rayset, "embree", 18.0, threads=2), 1.0, 30.0)]  # another thread count
        result = self.run_on(rows)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("Run noise: Embree's own rates spread over their repetitions by 3 % (median over its 9 rows), "
                      "at most 31 % (c diffuse, embree); 1 of 9 rows spread more than 10 %.", result.stdout)
        without = self.run_on([row("a", "primary", "embree", 10.0), row("a", "primary", "bvh8", 11.0)])
        self.assertNotIn("Run noise", without.stdout, "no sentence without the min and max columns")

    def test_build_times_get_their_range_and_a_slower_build_says_whether_noise_covers_it(self):
        rows = []
        for scene, (ours, lo, hi) in {"a": (110, 90, 130), "b": (120, 115, 125), "c": (80, 75, 85)}.items():
            for rayset in ("primary", "diffuse"):
                rows += [build_spread(row(scene, rayset, "embree", 10.0, build=100), 95, 105),
                         build_spread(row(scene, rayset, "bvh8", 11.0, build=ours), lo, hi)]
        out = self.run_on(rows, "--no-plot").stdout
        # Our fastest build against Embree's slowest, and the reverse: 90 / 105 and 130 / 95.
        self.assertIn("| 1.10 (0.86–1.37) |", out)
        # Counted once per scene, not once per ray set: b is slower even at its best, 115 / 105.
        self.assertIn("| default build ≤ 1.0 × Embree medium | max 1.20; 2 of 3 scenes above 1.0, 1 of them within "
                      "their min–max | **missed** |", out)

    def test_a_build_no_faster_with_more_threads_says_whether_noise_covers_it(self):
        rows = [build_spread(row("a", "primary", "embree", 10.0, build=100), 95, 105),
                build_spread(row("a", "primary", "bvh8", 9.0, build=1.0), 0.9, 1.1),
                build_spread(row("a", "primary", "embree", 18.0, build=60, threads=2), 55, 65),
                build_spread(row("a", "primary", "bvh8", 19.8, build=1.05, threads=2), 0.8, 1.2)]
        out = self.run_on(rows, "--no-plot").stdout
        # 1.0 / 1.05 ms: 0.95x, between 0.9 / 1.2 and 1.1 / 0.8.
        self.assertIn("Our default build, 1 → 2 threads: 0.95–0.95× faster (**missed**: faster on every scene; "
                      "1 of 1 scenes below 1.0, 1 of them within their min–max).", out)

    def test_with_out_a_picture_is_drawn_beside_the_markdown_and_linked_from_it(self):
        rows = []
        for rayset in ("primary", "diffuse", "shadow"):
            rows += [spread(row("a", rayset, "embree", 10.0), 9.0, 11.0), spread(row("a", rayset, "bvh8", 12.0), 11.0, 13.0),
                     spread(row("a", rayset, "bvh8:watertight", 9.0), 8.0, 9.5)]
        with tempfile.TemporaryDirectory() as d:
            md = os.path.join(d, "card.md")
            result = self.run_on(rows, "--out", md, directory=d)
            self.assertEqual(result.returncode, 0, result.stderr)
            with open(os.path.join(d, "card.png"), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
            with open(md) as f:
                self.assertIn("](card.png)", f.read())
            # --no-plot: Markdown only, no link to a picture that is not there.
            os.remove(os.path.join(d, "card.png"))
            self.assertEqual(self.run_on(rows, "--out", md, "--no-plot", directory=d).returncode, 0)
            self.assertFalse(os.path.exists(os.path.join(d, "card.png")))
            with open(md) as f:
                self.assertNotIn(".png", f.read())

    def test_a_picture_that_cannot_be_written_is_one_line_and_exit_2(self):
        rows = [row("a", "primary", "embree", 10.0), row("a", "primary", "bvh8", 12.0)]
        result = self.run_on(rows, "--plot", "/nonexistent-dir/card.png")
        self.assertEqual(result.returncode, 2)
        self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)
        self.assertIn("bvh-scorecard: error:", result.stderr)

    def test_each_backend_alone_is_held_to_every_row_against_embrees_best(self):
        rows = [row("a", "primary", "embree", 10.0), row("a", "primary", "bvh8", 12.0),
                row("a", "primary", "bvh8:sbvh", 8.0),
                row("b", "primary", "embree", 10.0), row("b", "primary", "bvh8", 9.0),
                row("b", "primary", "bvh8:sbvh", 11.0)]
        out = self.run_on(rows, "--no-plot").stdout
        # The pick per row meets 1.0 on both; neither backend alone does.
        self.assertIn("| our best ≥ 1.0 × Embree's best on every scene and ray set | min 1.10 | **met** |", out)
        self.assertIn("| bvh8 | 1.04 | - | - | 1.04 | 1 of 2 |", out)  # sqrt(1.2 * 0.9)
        self.assertIn("| bvh8:sbvh | 0.94 | - | - | 0.94 | 1 of 2 |", out)  # sqrt(0.8 * 1.1)

    def test_bad_input_is_one_line_and_exit_2(self):
        result = self.run_on([row("a", "uniform", "embree", 1.0)])
        self.assertEqual(result.returncode, 2)
        self.assertEqual(len(result.stderr.strip().splitlines()), 1)
        self.assertIn("bvh-scorecard: error:", result.stderr)


if __name__ == "__main__":
    unittest.main()
