"""Issue 30: a fair, paired comparison against any backend of the run. Timing runs in rounds
(round r traces every case of a scene once), so sample r of every row comes from the same
moment; `--reference NAME` (or `[defaults] reference`) makes ratio_to_reference the median over
rounds of (row sample / reference sample), and ratio_to_embree is the same against embree. Every
backend traces the screened rays: untraceable rays are misses for all (rays/screening.h).
"""
import math
import os
import re
import statistics
import unittest

import numpy as np

from cli_testing import CliTestCase, read_rows, run



def metadata(path):
    """The key = "value" lines of a .meta.toml."""
    with open(path) as f:
        return dict(re.findall(r'^(\w+) = "(.*)"$', f.read(), re.M))


def samples(row):
    return [float(x) for x in row["mrays_s_samples"].split(";")]


def paired_ratio(row, reference):
    """What the run must have written: the median of the per-round ratios."""
    return statistics.median(a / b for a, b in zip(samples(row), samples(reference), strict=True))


class ReferenceTest(CliTestCase):
    QUICK = ("--scene", "proc:sphere", "--rayset", "primary,shadow", "--rays", "2000", "--build-reps", "1",
             "--min-time", "0.002", "--warmup", "0")

    def run_quick(self, *args, out="run.csv"):
        return run("run", *self.QUICK, "--out", self.path(out), "--rays-dir", self.path("rays"), *args)

    def by_case(self, out="run.csv"):
        return {(r["rayset"], r["backend"]): r for r in read_rows(self.path(out))}

    def assertPairedRatios(self, rows, reference):
        for (rayset, backend), row in rows.items():
            ref = rows[(rayset, reference)]
            self.assertEqual(row["reference"], reference)
            expected = paired_ratio(row, ref)
            # The samples in the CSV carry 6 significant digits, the run's ratio the full ones.
            self.assertTrue(math.isclose(float(row["ratio_to_reference"]), expected, rel_tol=1e-4),
                            (rayset, backend, row["ratio_to_reference"], expected))
            embree = rows[(rayset, "embree")]
            self.assertTrue(math.isclose(float(row["ratio_to_embree"]), paired_ratio(row, embree), rel_tol=1e-4),
                            (rayset, backend, row["ratio_to_embree"]))
            if backend == reference:
                self.assertEqual(float(row["ratio_to_reference"]), 1.0)

    def test_every_row_has_one_sample_per_round_and_ratios_are_paired_by_round(self):
        result = self.run_quick("--backend", "embree,bvh2,bvh8", "--reps", "4")
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = self.by_case()
        self.assertEqual(len(rows), 6)
        for row in rows.values():
            self.assertEqual(row["reps"], "4")
            self.assertEqual(len(samples(row)), 4)
            self.assertEqual(row["plugin"], "")
        self.assertPairedRatios(rows, "embree")
        meta = metadata(self.path("run.meta.toml"))
        self.assertEqual(meta["timing"], "rounds")
        self.assertEqual(meta["reference_backend"], "embree")
        self.assertEqual(meta["agreement_backend"], "embree")
        for r in range(1, 5):
            self.assertIn(f"round {r}/4", result.stderr)
        self.assertIn("x embree", result.stdout)

    def test_reference_names_another_backend_and_ratio_to_embree_stays(self):
        result = self.run_quick("--backend", "embree,bvh2,bvh8", "--reps", "3", "--reference", "bvh2")
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = self.by_case()
        self.assertPairedRatios(rows, "bvh2")
        self.assertEqual(float(rows[("primary", "embree")]["ratio_to_embree"]), 1.0)
        self.assertEqual(metadata(self.path("run.meta.toml"))["reference_backend"], "bvh2")
        header = next(line for line in result.stdout.splitlines() if line.strip().startswith("rayset"))
        self.assertIn("x bvh2", header)
        # Agreement is still measured against Embree, whatever the timing reference.
        for row in rows.values():
            self.assertEqual(float(row["agree_hit"]), 1.0)

    def test_the_reference_comes_from_the_manifest_and_the_flag_overrides_it(self):
        suite = self.path("s.toml")
        with open(suite, "w") as f:
            f.write('[defaults]\nbackends = ["embree", "bvh2", "bvh8"]\nreference = "bvh8"\nrepetitions = 2\n'
                    '[[scene]]\nname = "ball"\npath = "proc:sphere"\n')
        result = run("run", "--suite", suite, "--rayset", "primary", "--rays", "2000", "--build-reps", "1",
                     "--min-time", "0.002", "--warmup", "0", "--out", self.path("m.csv"), "--rays-dir", self.path("rays"))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertPairedRatios(self.by_case("m.csv"), "bvh8")
        result = run("run", "--suite", suite, "--rayset", "primary", "--rays", "2000", "--build-reps", "1",
                     "--min-time", "0.002", "--warmup", "0", "--out", self.path("f.csv"), "--rays-dir", self.path("rays"),
                     "--reference", "bvh2")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertPairedRatios(self.by_case("f.csv"), "bvh2")

    def test_a_reference_that_is_not_one_of_the_runs_backends_is_one_line_and_nothing_is_written(self):
        for args, fragments in [
            (["--backend", "embree,bvh2", "--reference", "nope"], ["--reference", "nope is not one of the run's backends"]),
            (["--backend", "embree,bvh2", "--reference", "bvh8"], ["--reference", "bvh8", "(embree, bvh2)"]),
            (["--backend", "bvh2,bvh8", "--reference", "embree"], ["--reference", "embree", "(bvh2, bvh8)"]),
            (["--backend", "embree,bvh2", "--reference", ""], ["--reference", "must be one of the run's backend names"]),
            (["--backend", "embree,bvh2", "--reference", "embree,bvh2"], ["--reference", "one name"]),
        ]:
            with self.subTest(args=args):
                self.assertBadInput(self.run_quick("--reps", "1", *args), *fragments)
                self.assertFalse(os.path.exists(self.path("run.csv")))

    def test_a_manifest_reference_is_checked_naming_the_file_and_key(self):
        suite = self.path("s.toml")
        for value, fragment in [('"bvh8"', "bvh8 is not one of the run's backends (embree, bvh2)"),
                                ("3", "expected a string")]:
            with self.subTest(value=value):
                with open(suite, "w") as f:
                    f.write(f'[defaults]\nbackends = ["embree", "bvh2"]\nreference = {value}\n'
                            '[[scene]]\nname = "ball"\npath = "proc:sphere"\n')
                result = run("run", "--suite", suite, "--rays", "100", "--reps", "1", "--out", self.path("m.csv"),
                             "--rays-dir", self.path("rays"))
                self.assertBadInput(result, suite, "'defaults.reference'", fragment)
                self.assertFalse(os.path.exists(self.path("m.csv")))

    def test_a_run_without_embree_and_without_a_reference_has_no_ratios(self):
        result = self.run_quick("--backend", "bvh2,bvh8", "--reps", "2")
        self.assertEqual(result.returncode, 0, result.stderr)
        for row in read_rows(self.path("run.csv")):
            self.assertEqual((row["reference"], row["ratio_to_reference"], row["ratio_to_embree"]), ("", "", ""))
        self.assertEqual(metadata(self.path("run.meta.toml"))["reference_backend"], "")
        self.assertIn("x ref", result.stdout)


class ScreeningTest(CliTestCase):
    """`raybench trace` gives every backend the screened rays: NaN, Inf and out-of-range rays are
    misses whatever the backend, and a negative tnear traces as 0."""

    def test_untraceable_rays_are_misses_and_a_negative_tnear_is_zero_for_every_backend(self):
        good = [0.0, 0.0, 5.0, 0.0, 0.0, 0.0, -1.0, np.inf]  # straight at the unit sphere
        rays = [good]
        for field in range(8):
            for bad in (np.nan, np.inf, -np.inf, 1e30):
                if field == 7 and bad == np.inf:  # tfar = inf is the open interval
                    continue
                if field == 3 and bad in (-np.inf,):  # tnear = -inf is a negative tnear, traceable
                    continue
                ray = list(good)
                ray[field] = bad
                rays.append(ray)
        behind = list(good)
        behind[3] = -100.0  # reaches back through the sphere: a negative tnear is raised to 0
        rays.append(behind)
        path = self.path("rays.npy")
        np.save(path, np.array(rays, dtype=np.float32))
        untraceable = [i for i, r in enumerate(rays) if not all(abs(c) <= 1.844e18 for c in r[:3] + r[4:7])
                       or math.isnan(r[3]) or math.isnan(r[7])]
        self.assertGreater(len(untraceable), 20)
        for backend in ("embree", "bvh2", "bvh8", "reference"):
            with self.subTest(backend=backend):
                out, occ = self.path(f"{backend}.npy"), self.path(f"{backend}-occ.npy")
                result = run("trace", "--scene", "proc:sphere", "--rays", path, "-b", backend, "-o", out)
                self.assertEqual(result.returncode, 0, result.stderr)
                result = run("trace", "--scene", "proc:sphere", "--rays", path, "-b", backend, "--occluded", "-o", occ)
                self.assertEqual(result.returncode, 0, result.stderr)
                hits, occluded = np.load(out), np.load(occ)
                self.assertEqual(hits[0, 1] >= 0, True)
                for i in untraceable:
                    self.assertEqual((hits[i, 0], hits[i, 1], occluded[i, 0]), (np.inf, -1.0, 0.0), f"ray {i}")
                self.assertEqual(list(hits[-1]), list(hits[0]))  # tnear -100 traces as tnear 0


if __name__ == "__main__":
    unittest.main()
