"""scripts/plugin_boundary.py on synthetic runs: paired ratios per round, the 0.98 target, bad input."""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
COLUMNS = ["scene", "rayset", "backend", "threads", "mrays_s", "mrays_s_samples"]
PLUGIN = "plugin:plugins/raybench_bvh8_plugin.so"


def row(scene, rayset, backend, samples, threads=1):
    ordered_samples = sorted(samples)
    return {"scene": scene, "rayset": rayset, "backend": backend, "threads": threads,
            "mrays_s": ordered_samples[len(samples) // 2], "mrays_s_samples": ";".join(f"{s:g}" for s in samples)}


class PluginBoundary(unittest.TestCase):
    def run_on(self, *runs, timing="rounds"):
        """The script on one results CSV per list of rows (independent runs)."""
        with tempfile.TemporaryDirectory() as d:
            paths = []
            for i, rows in enumerate(runs):
                path = os.path.join(d, f"run{i}.csv")
                with open(path, "w", newline="") as f:
                    w = csv.DictWriter(f, COLUMNS)
                    w.writeheader()
                    w.writerows(rows)
                with open(os.path.join(d, f"run{i}.meta.toml"), "w") as f:
                    f.write(f'cpu = "Test CPU"\ncpu_id = "family 6"\ntiming = "{timing}"\nrepetitions = "3"\n')
                paths.append(path)
            return subprocess.run([sys.executable, os.path.join(HERE, "plugin_boundary.py"), *paths, "--plugin", PLUGIN,
                                   "--builtin", "bvh8"], capture_output=True, text=True)

    def test_ratios_are_paired_by_round_not_medians_of_medians(self):
        # Round 2 was slow for both: pairing cancels it, every paired ratio is 1.
        r = self.run_on([row("sponza", "primary", "bvh8", [10, 5, 10]),
                         row("sponza", "primary", PLUGIN, [10, 5, 10])])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("| sponza | primary | 10.000 | 10.000 | 1.000 | 1.000-1.000 | met |", r.stdout)
        self.assertIn("every row meets the target", r.stdout)

    def test_a_row_below_098_misses_and_says_whether_within_noise(self):
        r = self.run_on([row("sponza", "primary", "bvh8", [10, 10, 10]),
                         row("sponza", "primary", PLUGIN, [9.5, 9.6, 10.2]),
                         row("sponza", "shadow", "bvh8", [10, 10, 10]),
                         row("sponza", "shadow", PLUGIN, [9.0, 9.1, 9.2])])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("| 0.960 | 0.960-0.960 | missed |", r.stdout)
        self.assertIn("2 row(s) below the target: sponza/primary, sponza/shadow", r.stdout)

    def test_runs_are_pooled_and_their_spread_shown(self):
        # One process placed the plugin badly (0.90), two did not (1.0): the pooled median of the
        # nine pairs is 1.0, the runs' medians range from 0.90 to 1.00.
        def one_run(ratio):
            return [row("bunny", "primary", "bvh8", [10, 10, 10]),
                    row("bunny", "primary", PLUGIN, [10 * ratio] * 3)]
        r = self.run_on(one_run(0.9), one_run(1.0), one_run(1.0))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("| bunny | primary | 10.000 | 10.000 | 1.000 | 0.900-1.000 | met |", r.stdout)
        self.assertIn("3 run(s) of 3 rounds", r.stdout)

    def test_a_row_below_in_pool_but_reaching_1_in_one_run_is_within_the_spread(self):
        def one_run(ratio):
            return [row("bunny", "primary", "bvh8", [10, 10, 10]),
                    row("bunny", "primary", PLUGIN, [10 * ratio] * 3)]
        r = self.run_on(one_run(0.95), one_run(0.95), one_run(1.0))
        self.assertIn("| 0.950 | 0.950-1.000 | missed, within the runs' spread |", r.stdout)

    def test_two_thread_rows_and_other_backends_are_left_out(self):
        r = self.run_on([row("bunny", "diffuse", "bvh8", [4, 4, 4]), row("bunny", "diffuse", PLUGIN, [4, 4, 4]),
                         row("bunny", "diffuse", "bvh8", [8, 8, 8], threads=2),
                         row("bunny", "diffuse", "embree", [3, 3, 3])])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("over 1 rows", r.stdout)
        self.assertIn("Per ray set: diffuse 1.000.", r.stdout)

    def test_unpaired_samples_are_refused(self):
        r = self.run_on([row("bunny", "diffuse", "bvh8", [4, 4, 4]), row("bunny", "diffuse", PLUGIN, [4, 4])])
        self.assertEqual(r.returncode, 2)
        self.assertIn("one of each per round", r.stderr)

    def test_a_run_without_rounds_is_refused(self):
        r = self.run_on([row("bunny", "diffuse", "bvh8", [4, 4, 4]), row("bunny", "diffuse", PLUGIN, [4, 4, 4])],
                        timing="")
        self.assertEqual(r.returncode, 2)
        self.assertIn("not paired by round", r.stderr)

    def test_a_run_without_the_pair_is_refused(self):
        r = self.run_on([row("bunny", "diffuse", "bvh8", [4, 4, 4])])
        self.assertEqual(r.returncode, 2)
        self.assertIn("no scene and ray set has one-thread rows of both", r.stderr)


if __name__ == "__main__":
    unittest.main()
