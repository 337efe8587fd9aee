"""The gate within one run (issue 30): `raybench gate --current RUN.csv --candidate NAME`
holds each candidate row to the run's reference row of the same scene, ray set and threads,
round by round; `--json FILE` writes the verdicts of both gate modes; compare and the gate
against a baseline use each file's own reference and pair the samples of runs timed in
rounds. Driven on synthetic results and accuracy CSVs with the metadata `raybench run` writes
(timing = "rounds", reference_backend); the rule is in harness/src/results/compare.h and
harness/src/accuracy/accuracy_gate.h, the JSON schema in docs/gating.md.

Run through ctest (harness/tests/CMakeLists.txt sets RAYBENCH).
"""
import json
import math
import os
import unittest

from cli_testing import CliTestCase, run

# The results schema (harness/src/results/results_csv.cpp), in file order.
COLUMNS = ["scene", "triangles", "rayset", "query", "rays", "backend", "threads", "build_ms", "build_ms_min",
           "build_ms_max", "memory_bytes", "mrays_s", "mrays_s_min", "mrays_s_max", "reps", "mrays_s_samples",
           "ratio_to_embree", "hit_rate", "agree_hit", "agree_prim", "prim_ties", "t_relerr_max", "t_relerr_p999",
           "disagreements", "leaks", "sah_cost", "reference", "ratio_to_reference", "plugin"]
# The accuracy schema (harness/src/accuracy/accuracy_csv.cpp), in file order.
ACCURACY_COLUMNS = ["scene", "scale", "offset_x", "offset_y", "offset_z", "rayset", "query", "backend",
                    "accuracy_class", "rays", "invalid", "truth_hits", "ambiguous", "false_miss", "false_hit",
                    "wrong_prim", "self_hits", "ulp_p50", "ulp_p99", "ulp_max", "mrays_s", "mrays_s_min", "mrays_s_max"]

BASE, CAND = "plugin:base.so", "plugin:cand.so"
MACHINE = 'cpu = "test cpu"\nhardware_threads = "2"\ncompiler = "g++"\nflags = "-O2"\nbuild_type = "Release"\nembree = "3.13"\n'


def rounds_metadata(reference=BASE):
    return MACHINE + f'reference_backend = "{reference}"\ntiming = "rounds"\nstatus = "complete"\n'


# A busy machine: each round's speed swings by up to 40 %, for every backend of the round alike.
BUSY = [10.0, 6.5, 12.0, 8.0, 14.0, 7.0, 11.0, 9.0, 13.0]


def row(scene, backend, samples, rayset="primary", reference=BASE, **changes):
    r = {c: "0" for c in COLUMNS}
    r.update(scene=scene, triangles="100", rayset=rayset, query="intersect", rays="1000", backend=backend,
             threads="1", memory_bytes="4096", mrays_s=f"{sorted(samples)[len(samples) // 2]:.6g}",
             reps=str(len(samples)), mrays_s_samples=";".join(f"{v:.9g}" for v in samples), ratio_to_embree="",
             hit_rate="0.5", agree_hit="1", agree_prim="1", leaks="", sah_cost="", reference=reference,
             ratio_to_reference="1", plugin="")
    r.update(changes)
    return r


def run_rows(candidate_factors=(1.0,) * 9, reference_samples=BUSY, scenes=("terrain", "sphere"), **candidate_changes):
    """The reference and the candidate on each scene, candidate sample i = factor i x reference sample i."""
    rows = []
    for scene in scenes:
        rows.append(row(scene, BASE, reference_samples))
        rows.append(row(scene, CAND, [f * v for f, v in zip(candidate_factors, reference_samples)], **candidate_changes))
    return rows


def accuracy_row(scene, backend, rayset="primary", **errors):
    r = {c: "" for c in ACCURACY_COLUMNS}
    r.update(scene=scene, scale="1", offset_x="0", offset_y="0", offset_z="0", rayset=rayset, query="intersect",
             backend=backend, accuracy_class="fast", rays="10000", invalid="0", truth_hits="0.5", ambiguous="0",
             false_miss="0", false_hit="0", wrong_prim="0")
    r.update({k: str(v) for k, v in errors.items()})
    return r


class WithinRunTestCase(CliTestCase):
    def write(self, name, rows, metadata=None, columns=COLUMNS):
        path = self.path(name + ".csv")
        with open(path, "w") as f:
            f.write("\n".join([",".join(columns)] + [",".join(r[c] for c in columns) for r in rows]) + "\n")
        if metadata is not None:
            with open(self.path(name + ".meta.toml"), "w") as f:
                f.write(metadata)
        return path

    def write_run(self, name, rows, reference=BASE):
        return self.write(name, rows, rounds_metadata(reference))

    def gate(self, current, *args, candidates=(CAND,)):
        return run("gate", "--current", current, *[a for c in candidates for a in ("--candidate", c)], *args)

    def gate_json(self, current, *args, expect, **kwargs):
        """The gate with --json; its exit status must be `expect`; returns (result, the JSON read back)."""
        out = self.path("verdicts.json")
        if os.path.exists(out):
            os.remove(out)
        result = self.gate(current, "--json", out, *args, **kwargs)
        self.assertEqual(result.returncode, expect, result.stdout + result.stderr)
        with open(out) as f:
            return result, json.load(f)

    def assertFailure(self, verdicts, check, **fields):
        matching = [f for f in verdicts["failures"] if f["check"] == check
                    and all(f[k] == v for k, v in fields.items())]
        self.assertTrue(matching, f"no {check} failure with {fields} in {json.dumps(verdicts, indent=1)}")
        return matching[0]


class Speed(WithinRunTestCase):
    def test_a_clearly_slower_candidate_fails(self):
        # 30 % slower in every round, on a machine whose speed swings by 40 % from round to round.
        factors = [0.70, 0.72, 0.69, 0.71, 0.68, 0.70, 0.73, 0.70, 0.71]
        result, verdicts = self.gate_json(self.write_run("run", run_rows(factors)), expect=1)
        self.assertIn(f"FAIL: terrain/primary/{CAND}/threads:1: 30.0% slower than the reference {BASE} "
                      "(paired ratio 0.700 over 9 rounds, p = 0.002", result.stdout)
        self.assertIn("gate: FAIL", result.stdout)
        self.assertEqual(verdicts["verdict"], "fail")
        self.assertEqual(verdicts["mode"], "within-run")
        self.assertEqual(verdicts["reference"], BASE)
        f = self.assertFailure(verdicts, "speed", scene="terrain")
        self.assertEqual((f["rayset"], f["backend"], f["threads"]), ("primary", CAND, 1))
        self.assertAlmostEqual(f["value"], 0.70, places=6)
        self.assertAlmostEqual(f["p_value"], 1 / 512, places=9)  # every round slower: 2^-9
        self.assertEqual(f["limit"], 0.1)
        self.assertEqual(len(verdicts["failures"]), 2)  # both scenes
        # --verbose: every candidate row's paired ratio, its range and p.
        verbose = self.gate(self.path("run.csv"), "--verbose")
        self.assertEqual(verbose.stdout.split()[:7], ["scene", "rayset", "backend", "thr", "rounds", "x", BASE])
        self.assertEqual(verbose.stdout.splitlines()[1].split()[-5:], ["0.700", "[0.680", "-", "0.730]", "0.002"])

    def test_a_same_speed_noisy_candidate_passes(self):
        # Within 4 % of the reference either way, round by round, while the machine swings by 40 %.
        factors = [1.03, 0.97, 1.01, 0.96, 1.04, 0.99, 1.02, 0.98, 1.00]
        result, verdicts = self.gate_json(self.write_run("run", run_rows(factors)), expect=0)
        self.assertIn("gate: PASS", result.stdout)
        self.assertEqual(verdicts, {"verdict": "pass", "mode": "within-run", "reference": BASE,
                                    "current": [self.path("run.csv")], "baseline": [], "candidates": [CAND],
                                    "failures": [], "notes": []})

    def test_with_several_runs_a_slowdown_counts_only_when_every_run_shows_it(self):
        slower = [0.70, 0.72, 0.69, 0.71, 0.68, 0.70, 0.73, 0.70, 0.71]
        fluke = self.write_run("fluke", run_rows(slower))
        level = self.write_run("level", run_rows([1.0] * 9))
        again = self.write_run("again", run_rows(slower))
        result = self.gate(fluke, "--current", level)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn(f"terrain/primary/{CAND}/threads:1: slower in {fluke} but not in {level}: not counted",
                      result.stdout)
        result = self.gate(fluke, "--current", again)
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        self.assertIn(f"FAIL: terrain/primary/{CAND}/threads:1: 30.0% slower", result.stdout)

    def test_runs_gated_together_share_their_reference(self):
        first = self.write_run("first", run_rows())
        other = self.write("other", [row("terrain", CAND, BUSY, reference=CAND), row("terrain", BASE, BUSY, reference=CAND)],
                           rounds_metadata(CAND))
        result = self.gate(first, "--current", other)
        self.assertEqual(result.returncode, 2, result.stdout + result.stderr)
        self.assertIn("must share their reference", result.stderr)

    def test_slower_by_less_than_the_limit_passes(self):
        result = self.gate(self.write_run("run", run_rows([0.95] * 9)))
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)

    def test_slower_but_not_in_most_rounds_is_a_note(self):
        # Half the rounds far slower, half faster: the median drops, the signed-rank test does not confirm it.
        factors = [0.5, 1.2, 0.5, 1.1, 0.5, 1.3, 0.6, 1.2, 0.6]
        result, verdicts = self.gate_json(self.write_run("run", run_rows(factors)), expect=0)
        self.assertTrue(any("slower than the reference" in n and "not significant" in n for n in verdicts["notes"]),
                        verdicts["notes"])

    def test_too_few_rounds_to_ever_reach_alpha_is_a_note_naming_the_reps_needed(self):
        # alpha = 0.01 needs 7 rounds: 2^-6 = 0.016 is the smallest p that 6 can give.
        rows = run_rows([0.5] * 6, reference_samples=BUSY[:6])
        result, verdicts = self.gate_json(self.write_run("run", rows), expect=0)
        self.assertIn(f"note: terrain/primary/{CAND}/threads:1: 50.0% slower than the reference {BASE} (paired ratio "
                      "0.500), but 6 rounds can never give p < 0.01: re-run with --reps 7 or more", result.stdout)
        self.assertTrue(any("2 rows had 6 rounds or fewer" in n and "--reps 7" in n for n in verdicts["notes"]))
        # The same with 7 rounds fails.
        rows = run_rows([0.5] * 7, reference_samples=BUSY[:7])
        self.assertEqual(self.gate(self.write_run("seven", rows)).returncode, 1)
        # alpha = 0.05 needs 5 (2^-5 = 0.031): the 6 rounds fail.
        config = self.path("gate.toml")
        with open(config, "w") as f:
            f.write("alpha = 0.05\n")
        self.assertEqual(self.gate(self.path("run.csv"), "--config", config).returncode, 1)


class Accuracy(WithinRunTestCase):
    def test_lower_agreement_than_the_reference_fails(self):
        verdicts = self.gate_json(self.write_run("run", run_rows(agree_hit="0.9995")), expect=1)[1]
        f = self.assertFailure(verdicts, "agree_hit", scene="terrain")
        self.assertEqual((f["value"], f["against"], f["limit"]), (0.9995, 1, 0.0001))
        self.assertIn(f"agree_hit 0.9995 is 0.000500 below the reference {BASE}'s 1 (limit 0.0001)", f["message"])
        verdicts = self.gate_json(self.write_run("prim", run_rows(agree_prim="0.99")), expect=1)[1]
        self.assertFailure(verdicts, "agree_prim", scene="sphere")
        # Within the limit: a pass.
        self.gate_json(self.write_run("close", run_rows(agree_hit="0.99995")), expect=0)

    def test_more_leaks_than_the_reference_fails(self):
        rows = [row("sphere", BASE, BUSY, rayset="vertex-aimed", leaks="3"),
                row("sphere", CAND, BUSY, rayset="vertex-aimed", leaks="5")]
        verdicts = self.gate_json(self.write_run("run", rows), expect=1)[1]
        f = self.assertFailure(verdicts, "leaks", rayset="vertex-aimed")
        self.assertEqual((f["value"], f["against"]), (5, 3))
        # As many leaks as the reference (Embree's default mode leaks too): a pass.
        rows[1]["leaks"] = "3"
        self.gate_json(self.write_run("same", rows), expect=0)

    def test_more_referee_errors_than_the_reference_fail_per_kind(self):
        current = self.write_run("run", run_rows())
        accuracy = self.write("accuracy", [
            accuracy_row("terrain", BASE, false_miss=0.0001), accuracy_row("terrain", CAND, false_miss=0.0001),
            accuracy_row("sphere", BASE, false_hit=0.0002), accuracy_row("sphere", CAND, false_hit=0.0003, wrong_prim=0.0001),
        ], columns=ACCURACY_COLUMNS)
        result, verdicts = self.gate_json(current, "--accuracy", accuracy, expect=1)
        self.assertEqual(sorted(f["kind"] for f in verdicts["failures"]), ["false_hit", "wrong_prim"])
        f = self.assertFailure(verdicts, "referee", kind="false_hit")
        self.assertEqual((f["scene"], f["rayset"], f["backend"], f["threads"]), ("sphere", "primary", CAND, None))
        self.assertEqual((f["value"], f["against"]), (3, 2))
        self.assertIn(f"FAIL: sphere/primary/{CAND} (accuracy, intersect): false_hit 3 of 10000 rays, the reference {BASE} 2",
                      result.stdout)
        # As accurate as the reference: a pass.
        same = self.write("same", [accuracy_row(s, b) for s in ("terrain", "sphere") for b in (BASE, CAND)],
                          columns=ACCURACY_COLUMNS)
        self.gate_json(current, "--accuracy", same, expect=0)


class MissingRows(WithinRunTestCase):
    def test_a_candidate_or_reference_row_missing_fails(self):
        rows = [r for r in run_rows() if not (r["scene"] == "sphere" and r["backend"] == CAND)]
        rows.append(row("cube", CAND, BUSY))  # no reference row for the cube
        verdicts = self.gate_json(self.write_run("run", rows), expect=1)[1]
        self.assertEqual(sorted((f["scene"], f["check"]) for f in verdicts["failures"]),
                         [("cube", "missing"), ("sphere", "missing")])
        self.assertIn(f"no {CAND} row in", self.assertFailure(verdicts, "missing", scene="sphere")["message"])
        self.assertIn(f"no row of the reference {BASE}", self.assertFailure(verdicts, "missing", scene="cube")["message"])

    def test_a_partial_run_fails(self):
        # A candidate that crashed the process leaves the rows of the scenes before it.
        path = self.write("run", run_rows(scenes=("terrain",)),
                          rounds_metadata().replace('status = "complete"', 'status = "partial"\nprogress = "1 of 2 scenes"'))
        result, verdicts = self.gate_json(path, expect=1)
        f = self.assertFailure(verdicts, "missing")
        self.assertEqual((f["scene"], f["threads"]), ("", None))
        self.assertIn(f"FAIL: {path} is partial (1 of 2 scenes)", result.stdout)

    def test_a_candidate_missing_from_the_accuracy_csv_fails(self):
        current = self.write_run("run", run_rows())
        accuracy = self.write("accuracy", [accuracy_row("terrain", BASE), accuracy_row("terrain", CAND),
                                           accuracy_row("sphere", BASE)], columns=ACCURACY_COLUMNS)
        verdicts = self.gate_json(current, "--accuracy", accuracy, expect=1)[1]
        self.assertEqual([(f["scene"], f["check"]) for f in verdicts["failures"]], [("sphere", "missing")])


class BadInput(WithinRunTestCase):
    def assertNoJson(self, result, *fragments):
        self.assertBadInput(result, *fragments)
        self.assertFalse(os.path.exists(self.path("verdicts.json")))

    def test_a_candidate_the_run_does_not_have(self):
        current = self.write_run("run", run_rows())
        self.assertNoJson(self.gate(current, "--json", self.path("verdicts.json"), candidates=("plugin:typo.so",)),
                          "--candidate", "'plugin:typo.so' is not a backend of", f"it has {BASE}, {CAND}")
        self.assertBadInput(self.gate(current, candidates=(BASE,)), "is the run's reference")

    def test_a_run_not_timed_in_rounds(self):
        old = self.write("old", run_rows(), MACHINE)
        self.assertNoJson(self.gate(old, "--json", self.path("verdicts.json")), old, "not paired by round",
                          "re-run with this raybench")
        self.assertBadInput(self.gate(self.write("bare", run_rows())), "re-run with this raybench")

    def test_mixing_the_modes(self):
        current = self.write_run("run", run_rows())
        self.assertBadInput(run("gate", "--current", current), "--baseline", "--candidate")
        self.assertBadInput(self.gate(current, "--baseline", current), "give one or the other")
        self.assertBadInput(run("gate", "--baseline", current, "--current", current, "--accuracy", current), "--accuracy")
        self.assertBadInput(self.gate(current, "--json", current), "--json", "same file as the input")

    def test_samples_that_do_not_pair(self):
        rows = run_rows()
        rows[1]["mrays_s_samples"] = "7;7;7"
        path = self.write_run("run", rows)
        self.assertBadInput(self.gate(path), path, "line 3", "'mrays_s_samples'", "3 samples", "has 9")

    def test_a_reference_column_that_contradicts_the_metadata(self):
        rows = run_rows()
        rows[2]["reference"] = "embree"
        path = self.write_run("run", rows)
        self.assertBadInput(self.gate(path), path, "line 4", "column 'reference'", "reference_backend = 'plugin:base.so'")


class AgainstABaseline(WithinRunTestCase):
    """The gate against another run, and compare, with any reference and paired rounds."""

    def test_json_of_the_gate_against_a_baseline(self):
        baseline = self.write_run("baseline", run_rows([1.0] * 9))
        slower = self.write_run("slower", run_rows([0.8] * 9))
        out = self.path("verdicts.json")
        result = run("gate", "--baseline", baseline, "--current", slower, "--json", out)
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        self.assertIn(f"FAIL: terrain/primary/{CAND}/threads:1: ratio to {BASE} fell 20.0%", result.stdout)
        with open(out) as f:
            verdicts = json.load(f)
        self.assertEqual((verdicts["verdict"], verdicts["mode"], verdicts["reference"]), ("fail", "runs", BASE))
        self.assertEqual(verdicts["baseline"], [baseline])
        f = self.assertFailure(verdicts, "speed", scene="terrain")
        self.assertAlmostEqual(f["value"], 0.8, places=6)
        self.assertAlmostEqual(f["against"], 1.0, places=6)
        self.assertAlmostEqual(f["change"], -0.2, places=6)
        for failure in verdicts["failures"]:
            self.assertEqual(list(failure), ["scene", "rayset", "backend", "threads", "check", "kind", "message", "value",
                                             "against", "change", "p_value", "limit"])
            self.assertNotIn("\n", failure["message"])
        result = run("gate", "--baseline", baseline, "--current", baseline, "--json", out)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        with open(out) as f:
            self.assertEqual(json.load(f)["verdict"], "pass")

    def test_runs_with_different_references_are_bad_input(self):
        a = self.write_run("a", run_rows())
        rows = run_rows()
        for r in rows:
            r["reference"] = CAND
        b = self.write_run("b", rows, reference=CAND)
        self.assertBadInput(run("gate", "--baseline", a, "--current", b), b, a, "'plugin:cand.so'", "'plugin:base.so'")
        self.assertBadInput(run("compare", a, b), b, a, "different references")

    def test_compare_pairs_the_rounds_of_runs_timed_in_rounds(self):
        # The candidate is 0.8x the reference in every round of the second run, 1.0x in the first;
        # the machine's swings, shared by both backends of a round, cancel in the paired ratios.
        base = self.write_run("base", run_rows([1.0] * 9))
        current = self.write_run("current", run_rows([0.8] * 9, reference_samples=list(reversed(BUSY))))
        rows = json.loads(run("compare", base, current, "--format", "json").stdout)["rows"]
        cand = [r for r in rows if r["backend"] == CAND and r["scene"] == "terrain"][0]
        ratio = cand["ratio_to_reference"]
        self.assertAlmostEqual(ratio["base"], 1.0, places=9)
        self.assertAlmostEqual(ratio["current"], 0.8, places=9)
        self.assertEqual(ratio["verdict"], "slower")
        self.assertLess(ratio["p_value"], 1e-3)
        self.assertEqual(cand["ratio_to_embree"]["verdict"], "-")  # the reference is not embree
        reference = [r for r in rows if r["backend"] == BASE][0]
        self.assertIs(reference["reference"], True)
        self.assertEqual(reference["ratio_to_reference"]["verdict"], "reference")
        # Unpaired (files older than rounds), each sample over the reference's median: the swings stay.
        for name in ("base", "current"):
            with open(self.path(name + ".meta.toml"), "w") as f:
                f.write(MACHINE + f'reference_backend = "{BASE}"\n')
        rows = json.loads(run("compare", base, current, "--format", "json").stdout)["rows"]
        cand = [r for r in rows if r["backend"] == CAND and r["scene"] == "terrain"][0]
        self.assertNotEqual(cand["ratio_to_reference"]["verdict"], "slower")
        table = run("compare", base, current).stdout
        self.assertIn(f"x {BASE}", table.splitlines()[0])

    def test_an_older_file_without_reference_is_relative_to_embree(self):
        rows = [row("terrain", "embree", BUSY, reference=""), row("terrain", "bvh2", BUSY, reference="")]
        old = self.write("old", rows, MACHINE)
        js = json.loads(run("compare", old, old, "--format", "json").stdout)
        self.assertEqual(js["reference_backend"], "embree")
        bvh2 = [r for r in js["rows"] if r["backend"] == "bvh2"][0]
        self.assertEqual(bvh2["ratio_to_embree"], bvh2["ratio_to_reference"])


if __name__ == "__main__":
    unittest.main()
