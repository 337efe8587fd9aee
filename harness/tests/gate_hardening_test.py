"""`raybench compare` and `raybench gate` on the inputs of issue 28: neither passes on what it
cannot read as numbers. A file that cannot be read as results exits 2 with one line naming the
file, the row and the column; what the current run's code could have caused is a FAIL line
(exit 1) naming the row. The rule is written down in harness/src/results/compare.h.

Run through ctest (harness/tests/CMakeLists.txt sets RAYBENCH).
"""
import json
import unittest

from cli_testing import CliTestCase, run

# The results schema (harness/src/results/results_csv.cpp), in file order.
COLUMNS = ["scene", "triangles", "rayset", "query", "rays", "backend", "threads", "build_ms", "build_ms_min",
           "build_ms_max", "memory_bytes", "mrays_s", "mrays_s_min", "mrays_s_max", "reps", "mrays_s_samples",
           "ratio_to_embree", "hit_rate", "agree_hit", "agree_prim", "prim_ties", "t_relerr_max", "t_relerr_p999",
           "disagreements", "leaks", "sah_cost"]

# The same machine for every file, so that compare compares without --force.
METADATA = 'cpu = "test cpu"\nhardware_threads = "2"\ncompiler = "g++"\nflags = "-O2"\nbuild_type = "Release"\nembree = "3.13"\n'




def row(scene="terrain", backend="embree", rayset="primary", samples=(9.5, 10.0, 10.5), **changes):
    """A plausible results row; `changes` overrides columns by name."""
    r = {c: "0" for c in COLUMNS}
    r.update(scene=scene, triangles="100", rayset=rayset, query="intersect", rays="1000", backend=backend,
             threads="1", memory_bytes="4096", mrays_s="10", reps=str(len(samples)),
             mrays_s_samples=";".join(f"{v:.6g}" for v in samples), ratio_to_embree="1", hit_rate="0.5",
             agree_hit="1", agree_prim="1", leaks="", sah_cost="")
    r.update(changes)
    return r


def suite_rows(**bvh2_changes):
    """Two scenes, each with an Embree row and a bvh2 row; `bvh2_changes` applied to the bvh2 rows."""
    return [r for scene in ("terrain", "sphere")
            for r in (row(scene), row(scene, "bvh2", **bvh2_changes))]


class GateTestCase(CliTestCase):
    def write(self, name, rows, metadata=METADATA, prefix="", newline="\n"):
        """A results CSV (and its .meta.toml) in the test's folder."""
        path = self.path(name + ".csv")
        lines = [",".join(COLUMNS)] + [",".join(r[c] for c in COLUMNS) for r in rows]
        with open(path, "w", encoding="utf-8", newline="") as f:
            f.write(prefix + newline.join(lines) + newline)
        if metadata is not None:
            with open(self.path(name + ".meta.toml"), "w") as f:
                f.write(metadata)
        return path

    def gate(self, baseline, *currents):
        return run("gate", "--baseline", baseline, *[a for c in currents for a in ("--current", c)])


    def assertFails(self, result, *lines):
        """Exit 1, a FAIL line for each of `lines` (a prefix of it), and the summary says FAIL."""
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        fails = [line for line in result.stdout.splitlines() if line.startswith("FAIL: ")]
        for expected in lines:
            self.assertTrue(any(f.startswith("FAIL: " + expected) for f in fails), f"{expected!r} not in\n{result.stdout}")
        self.assertIn("gate: FAIL", result.stdout)


class UnreadableNumbersAreBadInput(GateTestCase):
    """Exit 2 naming the file, the row's line and key, and the column; compare refuses them too."""

    def assertRefusedByBoth(self, bad, good, *fragments):
        self.assertBadInput(self.gate(good, bad), bad, *fragments)
        self.assertBadInput(self.gate(bad, good), bad, *fragments)
        self.assertBadInput(run("compare", good, bad), bad, *fragments)
        self.assertBadInput(run("compare", bad, good), bad, *fragments)

    def test_every_throughput_sample_nan_empty_zero_negative_or_infinite(self):
        good = self.write("good", suite_rows())
        for name, samples in [("nan", "nan;nan;nan"), ("empty", ""), ("zero", "0;0;0"), ("negative", "-10;-10;-10"),
                              ("inf", "inf;inf;inf")]:
            with self.subTest(samples=samples):
                rows = suite_rows()
                for r in rows:
                    r["mrays_s_samples"] = samples
                bad = self.write(name, rows)
                self.assertRefusedByBoth(bad, good, "line 2 (terrain/primary/embree/threads:1)", "'mrays_s_samples'")

    def test_one_bad_sample_among_good_ones(self):
        good = self.write("good", suite_rows())
        bad = self.write("bad", suite_rows(mrays_s_samples="10;nan;10.5"))
        self.assertRefusedByBoth(bad, good, "line 3 (terrain/primary/bvh2/threads:1)", "'mrays_s_samples'",
                                 "sample 2 of 3 is 'nan'")

    def test_agreement_outside_0_to_1(self):
        good = self.write("good", suite_rows())
        for column in ("agree_hit", "agree_prim"):
            for value in ("1.5", "-0.1"):
                with self.subTest(column=column, value=value):
                    bad = self.write(f"{column}{value}", suite_rows(**{column: value}))
                    self.assertRefusedByBoth(bad, good, "line 3 (terrain/primary/bvh2/threads:1)", f"'{column}'",
                                             f"'{value}' is not a number in [0, 1]")

    def test_agreement_nan_or_empty(self):
        good = self.write("good", suite_rows())
        for value in ("nan", ""):
            with self.subTest(value=repr(value)):
                bad = self.write("bad", suite_rows(agree_hit=value))
                self.assertRefusedByBoth(bad, good, "line 3", "'agree_hit'")

    def test_agree_prim_may_be_empty_on_occlusion_rows_only(self):
        rows = suite_rows() + [row("terrain", b, rayset="shadow", query="occluded", agree_prim="") for b in ("embree", "bvh2")]
        path = self.write("shadow", rows)
        result = self.gate(path, path)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        intersect = self.write("intersect", suite_rows(agree_prim=""))
        self.assertBadInput(self.gate(path, intersect), intersect, "line 3", "'agree_prim'", "empty")

    def test_duplicate_rows_in_either_file(self):
        good = self.write("good", suite_rows())
        rows = suite_rows()
        duplicated = self.write("duplicated", rows + [rows[1]])
        self.assertRefusedByBoth(duplicated, good, "line 6 (terrain/primary/bvh2/threads:1) repeats line 3")

    def test_a_header_only_baseline_or_current(self):
        good = self.write("good", suite_rows())
        empty = self.write("empty", [])
        self.assertRefusedByBoth(empty, good, "no result rows")

    def test_a_baseline_without_the_embree_rows(self):
        current = self.write("current", suite_rows())
        no_embree = self.write("no_embree", [r for r in suite_rows() if r["backend"] != "embree"])
        self.assertBadInput(self.gate(no_embree, current), no_embree, "line 2 (terrain/primary/bvh2/threads:1)",
                            "no embree row for terrain/primary/threads:1")
        # Without embree for one scene only: still no reference for that scene's rows.
        half = self.write("half", [r for r in suite_rows() if not (r["backend"] == "embree" and r["scene"] == "sphere")])
        self.assertBadInput(self.gate(half, current), half, "sphere/primary/bvh2/threads:1", "no embree row")
        # A pooled baseline run without it is named, not silently left unscaled.
        self.assertBadInput(run("gate", "--baseline", current, "--baseline", half, "--current", current), half, "no embree row")


class ACurrentRunWithoutItsReferenceFails(GateTestCase):
    def test_a_current_run_without_the_embree_rows(self):
        baseline = self.write("baseline", suite_rows())
        no_embree = self.write("no_embree", [r for r in suite_rows() if r["backend"] != "embree"])
        self.assertFails(self.gate(baseline, no_embree),
                         "terrain/primary/bvh2/threads:1: no embree row for terrain/primary/threads:1 in " + no_embree,
                         "sphere/primary/bvh2/threads:1: no embree row",
                         "terrain/primary/embree/threads:1: in the baseline but not in the current run")

    def test_even_when_missing_rows_are_allowed(self):
        baseline = self.write("baseline", suite_rows())
        no_embree = self.write("no_embree", [r for r in suite_rows() if r["backend"] != "embree"])
        config = self.path("gate.toml")
        with open(config, "w") as f:
            f.write("fail_on_missing_rows = false\n")
        result = run("gate", "--baseline", baseline, "--current", no_embree, "--config", config)
        self.assertFails(result, "terrain/primary/bvh2/threads:1: no embree row")

    def test_identical_readable_files_still_pass(self):
        baseline = self.write("baseline", suite_rows())
        result = self.gate(baseline, self.write("same", suite_rows()))
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn("gate: PASS (4 rows compared", result.stdout)


class SpreadsheetFiles(GateTestCase):
    def test_a_csv_saved_by_excel_with_a_byte_order_mark_and_crlf(self):
        baseline = self.write("baseline", suite_rows())
        excel = self.write("excel", suite_rows(), prefix="\ufeff", newline="\r\n")
        with open(excel, "rb") as f:
            self.assertEqual(f.read(3), b"\xef\xbb\xbf")
        result = self.gate(baseline, excel)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn("gate: PASS", result.stdout)
        compared = run("compare", excel, baseline, "--format", "json")
        self.assertEqual(compared.returncode, 0, compared.stderr)
        self.assertEqual(len(json.loads(compared.stdout)["rows"]), 4)


class JsonOutput(GateTestCase):
    def test_a_control_character_in_a_name_is_escaped(self):
        rows = [row("tab\there"), row("tab\there", "bvh2")]
        path = self.write("tab", rows)
        result = run("compare", path, path, "--format", "json")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(json.loads(result.stdout)["rows"][0]["scene"], "tab\there")

    def test_the_reference_rows_have_ratio_1_as_in_the_csv(self):
        # Issue 29: Embree's rows said ratio 0 in JSON where the CSV and the table say 1 and "-".
        baseline = self.write("baseline", suite_rows())
        current = self.write("current", suite_rows(samples=(7.5, 8.0, 8.5)))
        result = run("compare", baseline, current, "--format", "json")
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = json.loads(result.stdout)["rows"]
        self.assertEqual(len(rows), 4)
        for r in rows:
            reference = r["backend"] == "embree"
            self.assertIs(r["reference"], reference, r)
            ratio = r["ratio_to_embree"]
            if reference:
                self.assertEqual(ratio, {"base": 1, "current": 1, "change": 0, "p_value": None,
                                         "verdict": "reference"})
            else:
                self.assertAlmostEqual(ratio["base"], 1.0, places=6)
                self.assertAlmostEqual(ratio["current"], 0.8, places=6)
                self.assertNotEqual(ratio["verdict"], "reference")

    def test_a_comparison_not_made_has_null_numbers(self):
        baseline = self.write("baseline", suite_rows())
        current = self.write("current", [dict(r, rays="2000") for r in suite_rows()])
        rows = json.loads(run("compare", baseline, current, "--format", "json").stdout)["rows"]
        bvh2 = [r for r in rows if r["backend"] == "bvh2"][0]
        self.assertIs(bvh2["same_rays"], False)
        for comparison in (bvh2["mrays_s"], bvh2["ratio_to_embree"]):
            self.assertEqual(comparison, {"base": None, "current": None, "change": None, "p_value": None,
                                          "verdict": "-"})


class PartialFiles(GateTestCase):
    PARTIAL = METADATA + 'status = "partial"\nprogress = "1 of 2 scenes"\n'

    def test_compare_and_gate_say_a_file_is_partial(self):
        baseline = self.write("baseline", suite_rows())
        partial = self.write("partial", [r for r in suite_rows() if r["scene"] == "terrain"], metadata=self.PARTIAL)
        note = f"{partial} is partial (1 of 2 scenes)"
        gated = self.gate(baseline, partial)
        self.assertIn("note: " + note, gated.stdout)
        self.assertFails(gated, "sphere/primary/bvh2/threads:1: in the baseline but not in the current run")
        compared = run("compare", baseline, partial)
        self.assertEqual(compared.returncode, 0, compared.stderr)
        self.assertIn("note: " + note, compared.stdout)
        self.assertIn(note, json.loads(run("compare", baseline, partial, "--format", "json").stdout)["notes"][0])
        complete = self.write("complete", suite_rows(), metadata=METADATA + 'status = "complete"\n')
        self.assertNotIn("partial", self.gate(baseline, complete).stdout)


class ManySamplesAndRows(GateTestCase):
    def test_compare_two_runs_with_30_repetitions(self):
        # The case: two real runs with --reps 30 (60 samples per row in all).
        suite = self.path("suite.toml")
        with open(suite, "w") as f:
            f.write('[defaults]\nrays = 2000\nbuild_repetitions = 1\nmin_time = 0.001\nwarmup = 0.0\n'
                    'raysets = ["primary"]\nbackends = ["embree", "bvh2"]\n'
                    '[[scene]]\nname = "terrain"\npath = "proc:terrain_spheres_small"\n')
        runs = []
        for name in ("a", "b"):
            out = self.path(name + ".csv")
            result = run("run", "--suite", suite, "--reps", "30", "--out", out, "--rays-dir", self.path("rays"))
            self.assertEqual(result.returncode, 0, result.stderr)
            runs.append(out)
        result = run("compare", *runs, "--format", "json")
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = json.loads(result.stdout)["rows"]
        self.assertEqual(len(rows), 2)
        for r in rows:
            self.assertTrue(0 < r["mrays_s"]["p_value"] <= 1, r)

    def test_30_repetitions_give_a_verdict(self):
        # 30 vs 30 samples: beyond the exact count, the normal approximation decides.
        base = [10 + 0.01 * k for k in range(30)]
        baseline = self.write("baseline", [row("terrain", b, samples=base) for b in ("embree", "bvh2")])
        slower = self.write("slower", [row("terrain", "embree", samples=base),
                                       row("terrain", "bvh2", samples=[0.8 * v for v in base])])
        js = json.loads(run("compare", baseline, slower, "--format", "json").stdout)
        bvh2 = [r for r in js["rows"] if r["backend"] == "bvh2"][0]
        self.assertEqual(bvh2["mrays_s"]["verdict"], "slower")
        self.assertLess(bvh2["mrays_s"]["p_value"], 1e-9)
        self.assertFails(self.gate(baseline, slower), "terrain/primary/bvh2/threads:1: ratio to embree fell 20.0%")

    def test_10000_rows_compare_and_gate(self):
        # 45 s before rows were matched through hash maps; ctest's TIMEOUT guards it.
        rows = [r for scene in range(5000) for r in (row(f"s{scene}"), row(f"s{scene}", "bvh2"))]
        baseline, current = self.write("baseline", rows), self.write("current", rows)
        gated = self.gate(baseline, current)
        self.assertEqual(gated.returncode, 0, gated.stdout[-2000:] + gated.stderr)
        self.assertIn("gate: PASS (10000 rows compared", gated.stdout)
        compared = run("compare", baseline, current, "--format", "json")
        self.assertEqual(compared.returncode, 0, compared.stderr)
        self.assertEqual(len(json.loads(compared.stdout)["rows"]), 10000)


if __name__ == "__main__":
    unittest.main()
