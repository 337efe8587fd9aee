"""scripts/bvh-scorecard on synthetic results: the right best backends, ratios and verdicts, for issue 4's
targets (Scorecard) and issue 33's per machine class (MachineScorecard)."""
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
            # Issue 4's targets, which these tests specify (issue 33's are the default: MachineScorecard).
            targets = [] if "--targets" in args else ["--targets", "issue4"]
            return subprocess.run([sys.executable, os.path.join(HERE, "bvh_scorecard.py"), path, *targets, *args],
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

    def test_run_takes_a_bare_raybench_name_from_path_and_a_path_from_where_it_was_given(self):
        with tempfile.TemporaryDirectory() as d:
            bare = scorecard_cli("--run", "--dry-run", "--machine-dir", d, "--raybench", "raybench")
            given = scorecard_cli("--run", "--dry-run", "--machine-dir", d, "--raybench", os.path.join(d, "raybench"))
        self.assertEqual(bare.returncode, 0, bare.stderr)
        self.assertEqual(bare.stdout.split()[0], "raybench")  # not <working directory>/raybench
        self.assertEqual(given.returncode, 0, given.stderr)
        self.assertEqual(given.stdout.split()[0], os.path.abspath(os.path.join(d, "raybench")))

    def test_run_with_out_or_plot_is_refused_in_one_line(self):
        with tempfile.TemporaryDirectory() as d:
            for extra in (("--out", os.path.join(d, "card.md")), ("--plot", os.path.join(d, "card.png"))):
                result = scorecard_cli("--run", "--dry-run", "--machine-dir", d, *extra)
                self.assertEqual(result.returncode, 2, extra)
                self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)
                self.assertIn("bvh-scorecard: error: --run writes", result.stderr)
                self.assertIn("no --out or --plot", result.stderr)
                self.assertEqual(result.stdout, "")  # no raybench command composed
            self.assertEqual(os.listdir(d), [])

    def test_bad_input_is_one_line_and_exit_2(self):
        result = self.run_on([row("a", "uniform", "embree", 1.0)])
        self.assertEqual(result.returncode, 2)
        self.assertEqual(len(result.stderr.strip().splitlines()), 1)
        self.assertIn("bvh-scorecard: error:", result.stderr)


INTEL = {"cpu": "Intel(R) Xeon(R) Processor", "cpu_id": "family 6 model 167 stepping 1, avx512f", "date": "2026-11-26T05:11:23Z",
         "git_commit": "f785ba42d4fcfb25c71ceb00acb3996adba828b3", "embree": "3.13.5"}
AMD = {"cpu": "AMD EPYC", "cpu_id": "family 26 model 2 stepping 1, avx512f", "date": "2026-11-23T07:35:16Z",
       "git_commit": "a393124ae9445b7bf9f006fb2c3900dac5d010ad"}


# The Embree lines of a real run's .meta.toml (build/raybench run --scene sponza_dabrovic,bunny --backend
# embree,bvh8 --rayset primary --reps 1 --rays 10000, issue 33's code), as raybench writes them.
REAL_EMBREE_META = """memory_policy = "huge pages for every backend (transparent, madvise)"
thp = "madvise"
provenance.embree.isa = "avx512"
provenance.embree.accel = "BVH8"
provenance.embree.leaf = "Triangle4"
provenance.embree.builder = "avx::BVH8BuilderSAH"
provenance.embree.intersector1 = "BVH8Triangle4Intersector1Moeller"
provenance.embree.frequency_level = "simd256"
provenance.embree.huge_pages = "on"
provenance.embree.embree_hugepages = "enabled"
provenance.embree.cpu = "Unknown CPU (GenuineIntel)"
provenance.embree.device_config = "verbose=0,hugepages=1,alloc_thread_block_size=2097088,frequency_level=simd256"
provenance.embree.summary = "ISA avx512, BVH8 Triangle4, intersector BVH8Triangle4Intersector1Moeller, frequency_level simd256, huge pages on"
"""


def toml_value(v):
    return "{" + ", ".join(f'"{k}" = {toml_value(x)}' for k, x in v.items()) + "}" if isinstance(v, dict) else f'"{v}"'


def write_run(directory, name, rows, meta):
    """A results CSV (with min/max columns when any row has them) and, unless meta is None, its .meta.toml."""
    path = os.path.join(directory, name + ".csv")
    columns = COLUMNS + [c for c in ("mrays_s_min", "mrays_s_max", "build_ms_min", "build_ms_max", "mrays_s_samples")
                         if any(c in r for r in rows)]
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns)
        w.writeheader()
        w.writerows(rows)
    if meta is not None:
        with open(os.path.join(directory, name + ".meta.toml"), "w") as f:
            f.writelines(f"{k} = {toml_value(v)}\n" for k, v in meta.items())
    return path


def scorecard_cli(*args):
    return subprocess.run([sys.executable, os.path.join(HERE, "bvh_scorecard.py"), *args], capture_output=True, text=True)


def issue33_run():
    """Scenes a and b, four ray kinds, one thread and two. Every target met except where noted."""
    rows = []
    for scene in ("a", "b"):
        for kind in ("primary", "diffuse", "shadow", "uniform"):
            bvh8 = 10.0 * (1.02 if (scene, kind) == ("b", "uniform") else 1.5)  # b uniform: bvh8 1.02 x embree
            high = 16.0 if (scene, kind) == ("a", "diffuse") else 9.0           # a diffuse: embree:high beats bvh8
            watertight = 10.0 * (1.0 if (scene, kind) == ("a", "uniform") else 1.3)  # a uniform: watertight 1.0
            rows += [spread(row(scene, kind, "embree", 10.0, build=100), 9.9, 10.1),
                     spread(row(scene, kind, "embree:high", high, build=400), high - 0.1, high + 0.1),
                     spread(row(scene, kind, "bvh8", bvh8, build=80), bvh8 * 0.9, bvh8 * 1.1),
                     spread(row(scene, kind, "bvh8:sbvh:reinsert", 16.5 if scene == "a" else 17.0, build=300), 16.0, 17.5),
                     spread(row(scene, kind, "bvh8:watertight", watertight, build=90), watertight - 0.1, watertight + 0.1),
                     row(scene, kind, "embree", 18.0, build=60, threads=2),
                     row(scene, kind, "bvh8", 28.0, build=66 if scene == "b" else 50, threads=2)]  # b: 66 / 60 at 2
    return rows


def coherent_run():
    """Scenes a and b as meshes/coherent.toml runs them, one thread: Embree's best coherent mode is
    packet8 at 14, but on shadow-tiled rays its incoherent stream at 15 and on a shadow-tiled its
    incoherent 16-ray packets at 16; bvh8:packet 21 on the tiled rows but 17 on b shadow-tiled, and
    0.91 x bvh8 on b uniform."""
    rows = []
    for scene in ("a", "b"):
        for kind in ("primary-tiled", "shadow-tiled", "diffuse", "uniform"):
            tiled = kind.endswith("-tiled")
            packet = 17.0 if (scene, kind) == ("b", "shadow-tiled") else 21.0 if tiled else \
                10.0 if (scene, kind) == ("b", "uniform") else 10.8
            incoherent_stream = 15.0 if kind == "shadow-tiled" else 11.0
            rows += [spread(row(scene, kind, "embree", 10.0), 9.9, 10.1),
                     row(scene, kind, "embree:packet4", 12.0),
                     spread(row(scene, kind, "embree:packet8", 14.0), 13.9, 14.1),
                     row(scene, kind, "embree:stream", 13.0),
                     spread(row(scene, kind, "embree:stream:incoherent", incoherent_stream), incoherent_stream - 0.1,
                            incoherent_stream + 0.1),
                     row(scene, kind, "embree:packet16:incoherent", 16.0 if (scene, kind) == ("a", "shadow-tiled") else 9.0),
                     spread(row(scene, kind, "bvh8", 11.0), 10.9, 11.1),
                     spread(row(scene, kind, "bvh8:packet", packet), packet - 1.0, packet + 1.0)]
    return rows


class MachineScorecard(unittest.TestCase):
    def test_a_machine_class_is_the_cpus_vendor_family_and_model(self):
        from machine_scorecard import machine_class
        from report import InputError
        self.assertEqual(machine_class(INTEL), "intel-family6-model167")
        self.assertEqual(machine_class(AMD), "amd-family26-model2")
        self.assertEqual(machine_class({"cpu": "AuthenticAMD", "cpu_id": "family 25 model 17 stepping 1, avx512f"}),
                         "amd-family25-model17")
        self.assertEqual(machine_class({"cpu": "Ampere Altra", "cpu_id": "family 8 model 1 stepping ?, sse"}),
                         "unknown-family8-model1")
        for meta in ({"cpu": "AMD EPYC"}, {"cpu": "AMD EPYC", "cpu_id": "family ? model ? stepping ?, sse"}):
            with self.assertRaisesRegex(InputError, "cannot name the machine class"):
                machine_class(meta)

    def test_issue33s_targets_name_the_rows_that_miss_and_whether_noise_covers_them(self):
        with tempfile.TemporaryDirectory() as d:
            result = scorecard_cli(write_run(d, "run", issue33_run(), INTEL), "--no-plot")
        self.assertEqual(result.returncode, 0, result.stderr)
        out = result.stdout
        self.assertIn("# Scorecard of machine class intel-family6-model167", out)
        self.assertIn("CPU: Intel(R) Xeon(R) Processor (family 6 model 167 stepping 1, avx512f); ISA: avx512f", out)
        # A uniform row like any other: bvh8 15 / 10, against embree:high 9, our best 16.5 / 10.
        self.assertIn("| a | uniform | 1.50 (1.34–1.67) | 1.50 (1.34–1.67) | bvh8:sbvh:reinsert | 1.65 (1.58–1.77) | "
                      "1.00 (0.98–1.02) |", out)
        self.assertIn("## Issue 33's targets: 2 of 7 met", out)
        # b uniform: 10.2 / 10, reaching 11.22 / 9.9 = 1.13 at best: within noise.
        self.assertIn("| `bvh8` ≥ 1.05 × `embree`, every row (primary, diffuse, shadow, uniform) | min 1.02 (b uniform); "
                      "1 of 8 rows below 1.05 | **missed** |", out)
        self.assertIn("b uniform 1.02 (0.91–1.13), within noise.", out)
        # a diffuse: 15 / 16 against embree:high, at best 16.5 / 15.9 = 1.04.
        self.assertIn("min 0.94 (a diffuse); 1 of 8 rows below 1.00 | **missed** |", out)
        # Our best 16.5 or 17 / Embree's best (16 on a diffuse, else 10): one row at 1.03, within noise
        # (17.5 / 15.9 = 1.10 reaches it).
        self.assertIn("a diffuse 1.03 (0.99–1.10), within noise", out)
        self.assertIn("| our best ≥ 1.30 × Embree's best, geometric mean over primary, diffuse, shadow | 1.55 over 6 rows "
                      "| **met** |", out)
        # a uniform: watertight 10 / 10, at best 10.1 / 9.9 = 1.02: beyond noise.
        self.assertIn("| watertight ≥ 1.05 × `embree`, every row (primary, diffuse, shadow, uniform) | min 1.00 (a uniform); "
                      "1 of 8 rows below 1.05 | **missed** |", out)
        self.assertIn("a uniform 1.00 (0.98–1.02), beyond noise.", out)
        self.assertIn("| default build (`bvh8`) ≤ 1.0 × Embree's medium build, 1 thread | max 0.80 (a) | **met** |", out)
        self.assertIn("| default build (`bvh8`) ≤ 1.0 × Embree's medium build, 2 threads | max 1.10 (b); 1 of 2 scenes "
                      "above 1.00 | **missed** |", out)
        self.assertIn("Embree 3.13.5: ISA not recorded; BVH type not recorded; memory policy not recorded.", out)
        # A run without Embree provenance predates issue 33's Embree wrapper fix: its ratios overstate ours.
        self.assertIn("This run predates issue 33's Embree wrapper fix and memory policy (its metadata records no Embree "
                      "provenance): Embree was traced through a slower loop, so its ratios overstate ours.", out)

    def test_the_coherent_section_holds_our_best_packet_mode_to_embrees_best_coherent_mode(self):
        with tempfile.TemporaryDirectory() as d:
            result = scorecard_cli(write_run(d, "run", coherent_run(), INTEL), "--no-plot")
        self.assertEqual(result.returncode, 0, result.stderr)
        out = result.stdout
        self.assertIn("## Coherent rays (issue 32)", out)
        # Embree's best coherent mode is the fastest of its packet and stream modes, whatever their
        # context flag: 21 / 14 (embree:packet8) and 21 / 10 on primary-tiled; on shadow-tiled
        # 21 / 16 (embree:packet16:incoherent) on a, 17 / 15 (embree:stream:incoherent) on b.
        self.assertIn("| a | primary-tiled | bvh8:packet | embree:packet8 | 1.50 (1.42–1.58) | 2.10 (1.98–2.22) |", out)
        self.assertIn("| a | shadow-tiled | bvh8:packet | embree:packet16:incoherent | 1.31 | 2.10 (1.98–2.22) |", out)
        self.assertIn("| b | shadow-tiled | bvh8:packet | embree:stream:incoherent | 1.13 (1.06–1.21) | 1.70 (1.58–1.82) |",
                      out)
        self.assertIn("### Issue 32's targets: 0 of 3 met", out)
        # b shadow-tiled reaches 18 / 14.9 = 1.21 at best: beyond noise.
        self.assertIn("| our best coherent ≥ 1.30 × Embree's best coherent mode, every row (primary-tiled, shadow-tiled) "
                      "| min 1.13 (b shadow-tiled); 1 of 4 rows below 1.30 | **missed** |", out)
        self.assertIn("b shadow-tiled 1.13 (1.06–1.21), beyond noise", out)
        # (2.1^3 x 1.7)^(1/4) = 1.99.
        self.assertIn("| our best coherent ≥ 2.0 × `embree` (rtcIntersect1), geometric mean over primary-tiled, "
                      "shadow-tiled | 1.99 over 4 rows | **missed** |", out)
        # On incoherent rays: 10.8 / 11 = 0.98, but b uniform 10 / 11 = 0.91, reaching 11 / 10.9 = 1.01: within noise.
        self.assertIn("| a | diffuse | bvh8:packet / bvh8 | 0.98 (0.88–1.08) |", out)
        self.assertIn("| every packet backend of ours ≥ 0.95 × itself without `packet`, every row (diffuse, uniform) "
                      "| min 0.91 (b uniform); 1 of 4 rows below 0.95 | **missed** |", out)
        self.assertIn("b uniform 0.91 (0.81–1.01), within noise", out)

    def test_the_coherent_targets_are_met_and_not_measurable_as_the_run_says(self):
        rows = [r for r in coherent_run() if not (r["scene"] == "b" and r["backend"] == "bvh8:packet")]
        with tempfile.TemporaryDirectory() as d:
            out = scorecard_cli(write_run(d, "run", rows, INTEL), "--no-plot").stdout
        self.assertIn("| our best coherent ≥ 1.30 × Embree's best coherent mode, every row (primary-tiled, shadow-tiled) "
                      "| min 1.31 (a shadow-tiled) | **met** |", out)
        self.assertIn("| 2.10 over 2 rows | **met** |", out)
        self.assertIn("### Issue 32's targets: 3 of 3 met", out)
        # Without Embree's coherent modes the first target cannot be measured; without the tiled rows
        # the second neither; a run without any packet backend of ours has no coherent section at all.
        no_embree_modes = [r for r in rows if not r["backend"].startswith("embree:")]
        with tempfile.TemporaryDirectory() as d:
            out = scorecard_cli(write_run(d, "run", no_embree_modes, INTEL), "--no-plot").stdout
        self.assertIn("| no rows: no Embree packet or stream mode beside a packet backend of ours | **not measurable** |", out)
        untiled = [r for r in rows if not r["rayset"].endswith("-tiled")]
        with tempfile.TemporaryDirectory() as d:
            out = scorecard_cli(write_run(d, "run", untiled, INTEL), "--no-plot").stdout
        self.assertIn("| our best coherent ≥ 2.0 × `embree` (rtcIntersect1), geometric mean over primary-tiled, "
                      "shadow-tiled | no rows | **not measurable** |", out)
        single = [r for r in rows if "packet" not in r["backend"]]
        with tempfile.TemporaryDirectory() as d:
            out = scorecard_cli(write_run(d, "run", single, INTEL), "--no-plot").stdout
        self.assertIn("## Issue 33's targets", out)
        self.assertNotIn("Coherent rays", out)

    def test_targets_issue32_is_the_coherent_card_alone_written_beside_the_machine_scorecard(self):
        with tempfile.TemporaryDirectory() as d:
            run = write_run(d, "run", coherent_run(), INTEL)
            cards = os.path.join(d, "cards")
            os.mkdir(cards)
            result = scorecard_cli(run, "--targets", "issue32", "--machine-dir", cards)
            self.assertEqual(result.returncode, 0, result.stderr)
            with open(os.path.join(cards, "intel-family6-model167-coherent.md"), encoding="utf-8") as f:
                out = f.read()
            self.assertTrue(os.path.exists(os.path.join(cards, "intel-family6-model167-coherent.png")))
            with open(os.path.join(cards, "README.md"), encoding="utf-8") as f:
                index = f.read()
            # Not a class's issue-33 scorecard: only the header and issue 32's section.
            self.assertFalse(os.path.exists(os.path.join(cards, "intel-family6-model167.md")))
            self.assertIn("# Scorecard of machine class intel-family6-model167: coherent rays", out)
            self.assertNotIn("Issue 33's targets", out)
            self.assertIn("### Issue 32's targets: 0 of 3 met", out)
            self.assertIn("![ours against Embree's best coherent mode", out)
            self.assertIn("[intel-family6-model167](intel-family6-model167-coherent.md)", index)
            # A run without a packet backend of ours has no coherent card: one line, exit 2.
            single = write_run(d, "single", [r for r in coherent_run() if "packet" not in r["backend"]], INTEL)
            refused = scorecard_cli(single, "--targets", "issue32", "--no-plot")
            self.assertEqual(refused.returncode, 2)
            self.assertEqual(len(refused.stderr.strip().splitlines()), 1, refused.stderr)
            self.assertIn("no single-thread tiled, diffuse or uniform rows with a packet backend of ours", refused.stderr)

    def test_a_target_whose_rows_the_run_lacks_is_not_measurable_never_met(self):
        rows = [r for r in issue33_run() if r["rayset"] != "uniform" and r["threads"] == 1]
        with tempfile.TemporaryDirectory() as d:
            out = scorecard_cli(write_run(d, "run", rows, AMD), "--no-plot").stdout
        self.assertIn("| `bvh8` ≥ 1.05 × `embree`, every row (primary, diffuse, shadow, uniform) | min 1.50 (a primary); "
                      "the run has no uniform rows | **not measurable** |", out)
        self.assertIn("| default build (`bvh8`) ≤ 1.0 × Embree's medium build, 2 threads | no rows: no 2-thread rows of "
                      "bvh8 and embree | **not measurable** |", out)
        self.assertIn("## Issue 33's targets: 2 of 7 met", out)

    def test_the_header_names_embrees_isa_bvh_and_memory_policy_from_the_keys_raybench_writes(self):
        with tempfile.TemporaryDirectory() as d:
            path = write_run(d, "run", issue33_run(), INTEL)
            with open(os.path.join(d, "run.meta.toml"), "a") as f:
                f.write(REAL_EMBREE_META)
            out = scorecard_cli(path, "--no-plot").stdout
        self.assertIn("Embree 3.13.5: ISA avx512; BVH type BVH8 Triangle4; memory policy huge pages for every backend "
                      "(transparent, madvise).", out)
        self.assertNotIn("predates", out)

    def test_embree_backends_that_differ_are_named_and_huge_pages_stand_in_for_a_missing_run_policy(self):
        meta = {**INTEL, "provenance": {"embree": {"isa": "avx2", "accel": "BVH4", "leaf": "Triangle4", "huge_pages": "on"},
                                        "embree:high": {"isa": "avx2", "accel": "BVH8", "leaf": "Triangle4v",
                                                        "huge_pages": "on"}}}
        with tempfile.TemporaryDirectory() as d:
            out = scorecard_cli(write_run(d, "run", issue33_run(), meta), "--no-plot").stdout
        self.assertIn("Embree 3.13.5: ISA avx2; BVH type embree: BVH4 Triangle4; embree:high: BVH8 Triangle4v; memory "
                      "policy huge pages on.", out)
        self.assertNotIn("predates", out)

    def test_machine_dir_writes_the_class_scorecard_and_an_index_of_every_class(self):
        with tempfile.TemporaryDirectory() as d:
            cards = os.path.join(d, "scorecards")
            os.mkdir(cards)
            # The Intel run records Embree's provenance (issue 33's code), the AMD one does not.
            intel = dict(INTEL, provenance={"embree": {"isa": "avx512", "accel": "BVH8", "leaf": "Triangle4"}})
            for name, meta in (("intel", intel), ("amd", AMD)):
                result = scorecard_cli(write_run(d, name, issue33_run(), meta), "--machine-dir", cards)
                self.assertEqual(result.returncode, 0, result.stderr)
            self.assertEqual(sorted(os.listdir(cards)), ["README.md", "amd-family26-model2.md", "amd-family26-model2.png",
                                                         "intel-family6-model167.md", "intel-family6-model167.png"])
            with open(os.path.join(cards, "intel-family6-model167.md")) as f:
                self.assertIn("](intel-family6-model167.png)", f.read())
            with open(os.path.join(cards, "README.md")) as f:
                index = f.read()
            # One line per class, by name; our best's geometric mean over the primary, diffuse and shadow rows;
            # a run without Embree's provenance (the AMD one) said to predate issue 33's Embree wrapper fix.
            amd = index.index("| [amd-family26-model2](amd-family26-model2.md) | AMD EPYC | avx512f | 2026-11-23 | `a393124` | "
                              "1.55 | 1.43 | 2 of 7; measured before issue 33's Embree wrapper fix (its ratios overstate ours) |")
            intel = index.index("| [intel-family6-model167](intel-family6-model167.md) | Intel(R) Xeon(R) Processor | avx512f | "
                                "2026-11-26 | `f785ba4` | 1.55 | 1.43 | 2 of 7 |")
            self.assertLess(amd, intel)
            # --index alone regenerates it from the scorecards present.
            os.remove(os.path.join(cards, "amd-family26-model2.md"))
            result = scorecard_cli("--index", cards)
            self.assertEqual(result.returncode, 0, result.stderr)
            # It prints the table for the README's headline, linked from where it was run.
            self.assertIn(f"| [intel-family6-model167]({os.path.relpath(cards)}/intel-family6-model167.md) |", result.stdout)
            with open(os.path.join(cards, "README.md")) as f:
                index = f.read()
            self.assertNotIn("amd-family26-model2", index)
            self.assertIn("intel-family6-model167", index)

    def test_both_target_sets_in_one_scorecard(self):
        with tempfile.TemporaryDirectory() as d:
            out = scorecard_cli(write_run(d, "run", issue33_run(), AMD), "--targets", "issue33,issue4", "--no-plot").stdout
        self.assertIn("## Issue 33's targets: 2 of 7 met", out)
        self.assertIn("## Issue 4's targets (the earlier set)", out)
        self.assertIn("| geometric mean ≥ 1.10 | 1.55 | **met** |", out)

    def test_run_composes_the_one_raybench_command_of_a_machines_scorecard(self):
        with tempfile.TemporaryDirectory() as d:
            result = scorecard_cli("--run", "--dry-run", "--machine-dir", d, "--", "--scene", "bunny")
        self.assertEqual(result.returncode, 0, result.stderr)
        command = result.stdout.strip().split()
        self.assertEqual(command[:2], ["build/raybench", "run"])
        backends = command[command.index("--backend") + 1].split(",")
        for b in ("embree", "embree:high", "bvh8", "bvh8:reinsert", "bvh8:sbvh:reinsert", "bvh8:watertight"):
            self.assertIn(b, backends)
        self.assertEqual(command[command.index("--rayset") + 1], "primary,diffuse,shadow,uniform")
        self.assertEqual(command[command.index("--threads") + 1], "1,2")
        self.assertRegex(command[command.index("--out") + 1], r"/(intel|amd|unknown)-family\d+-model\d+-run\.csv$")
        self.assertEqual(command[-2:], ["--scene", "bunny"])

    def test_a_run_timed_in_rounds_gives_each_ratio_as_the_median_of_its_per_round_ratios(self):
        # a primary: bvh8 16, 12, 8 against embree 10, 8, 5 (a slower third round hitting both). Per
        # round 1.6, 1.5, 1.6: paired, 1.60 (1.50–1.60); the medians' ratio would read 12 / 8 = 1.50 and
        # its range 8 / 10 to 16 / 5 (0.80–3.20), comparing Embree's quiet rounds with bvh8's busy ones.
        rows = issue33_run()
        for r in rows:
            if (r["scene"], r["rayset"], r["threads"]) == ("a", "primary", 1) and r["backend"] in ("embree", "bvh8"):
                samples = [16.0, 12.0, 8.0] if r["backend"] == "bvh8" else [10.0, 8.0, 5.0]
                r.update(mrays_s=samples[1], mrays_s_min=min(samples), mrays_s_max=max(samples),
                         mrays_s_samples=";".join(map(str, samples)))
        with tempfile.TemporaryDirectory() as d:
            paired = scorecard_cli(write_run(d, "paired", rows, {**INTEL, "timing": "rounds"}), "--no-plot").stdout
            unpaired = scorecard_cli(write_run(d, "unpaired", rows, INTEL), "--no-plot").stdout
            bad = scorecard_cli(write_run(d, "bad", [{**r, "mrays_s_samples": "12;x"} if "mrays_s_samples" in r else r
                                                     for r in rows], {**INTEL, "timing": "rounds"}), "--no-plot")
        self.assertIn("| a | primary | 1.60 (1.50–1.60) |", paired)
        # Rows without samples (every other pair here) keep the medians' ratio and the extremes' range.
        self.assertIn("| a | diffuse | 1.50 (1.34–1.67) |", paired)
        # A run whose samples are not paired by round (no timing = "rounds"): the medians' ratio.
        self.assertIn("| a | primary | 1.50 (0.80–3.20) |", unpaired)
        self.assertEqual(bad.returncode, 2)
        self.assertIn("a/primary/embree/threads 1: mrays_s_samples must be positive numbers", bad.stderr)

    def test_bad_input_is_one_line_and_exit_2(self):
        with tempfile.TemporaryDirectory() as d:
            no_meta = write_run(d, "no-meta", issue33_run(), None)
            no_cpu = write_run(d, "no-cpu", issue33_run(), {"date": "2026-11-26"})
            bad_columns = os.path.join(d, "bad.csv")
            with open(bad_columns, "w") as f:
                f.write("scene,rayset,backend\na,primary,embree\n")
            with open(os.path.join(d, "bad.meta.toml"), "w") as f:
                f.write('cpu_id = "family 6 model 167 stepping 1, avx512f"\n')
            for args, message in (((no_meta, "--no-plot"), "no metadata beside it"),
                                  ((no_cpu, "--machine-dir", d), "cannot name the machine class"),
                                  ((bad_columns, "--no-plot"), "missing columns: threads"),
                                  (("--index", os.path.join(d, "absent")), "not a directory")):
                result = scorecard_cli(*args)
                self.assertEqual(result.returncode, 2, args)
                self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)
                self.assertIn("bvh-scorecard: error:", result.stderr)
                self.assertIn(message, result.stderr)
            self.assertEqual(scorecard_cli(no_meta, "--targets", "issue5").returncode, 2)


if __name__ == "__main__":
    unittest.main()
