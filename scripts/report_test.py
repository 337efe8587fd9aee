"""scripts/report driven as a user drives it, on small synthetic results CSVs: the report and
every PNG it links exist and are real images, the tables hold every (scene, backend) pair, an
accuracy file gives the speed-versus-error plots, and bad input exits 2 with one line on stderr
and writes nothing.

    /usr/bin/python3 -m unittest scripts/report_test.py     (from the repository root)
    /usr/bin/python3 scripts/report_test.py                 (from anywhere)
"""
import csv
import os
import random
import re
import subprocess
import tempfile
import unittest

REPORT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "report")

# raybench's results schema (README, "Results").
COLUMNS = ["scene", "triangles", "rayset", "query", "rays", "backend", "threads", "build_ms",
           "build_ms_min", "build_ms_max", "memory_bytes", "mrays_s", "mrays_s_min",
           "mrays_s_max", "reps", "mrays_s_samples", "ratio_to_embree", "hit_rate", "agree_hit",
           "agree_prim", "prim_ties", "t_relerr_max", "t_relerr_p999", "disagreements"]
SCENES = {"bunny": 69451, "proc:terrain_spheres": 1000448}  # a name with ':' on purpose
BACKENDS = ["embree", "bvh2", "bvh2:watertight"]
RAYSETS = {"primary": "intersect", "shadow": "occluded"}
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
MIN_PNG_BYTES = 4096

META = """# What the results beside this file depend on (written by raybench).
date = "2026-01-02T03:04:05Z"
cpu = "Test CPU 9000"
hardware_threads = "2"
compiler = "GNU 12.2.0"
build_type = "Release"
flags = "-O3 -march=native"
embree = "3.13.5"
git_commit = "0123456789abcdef-dirty"
threads = "1"
rays = "4096"
repetitions = "5"
"""


def results_rows(threads_list=(1,), seed=1):
    """Plausible rows: Embree fastest, shadow rays (occlusion) with empty agree_prim & co."""
    rng = random.Random(seed)
    rows = []
    for scene, triangles in SCENES.items():
        for rayset, query in RAYSETS.items():
            for threads in threads_list:
                embree_speed = rng.uniform(2, 30) * threads
                for backend in BACKENDS:
                    speed = embree_speed * (1 if backend == "embree" else rng.uniform(0.3, 0.9))
                    samples = [speed * rng.uniform(0.9, 1.1) for _ in range(5)] + [speed]
                    occluded = query == "occluded"
                    agree_hit = 1 if backend == "embree" else 1 - rng.choice([0, 2, 30]) / 4096
                    rows.append({
                        "scene": scene, "triangles": triangles, "rayset": rayset, "query": query,
                        "rays": 4096, "backend": backend, "threads": threads,
                        "build_ms": 12.5, "build_ms_min": 12, "build_ms_max": 14,
                        "memory_bytes": 3 * 2 ** 20, "mrays_s": speed,
                        "mrays_s_min": min(samples), "mrays_s_max": max(samples), "reps": 5,
                        "mrays_s_samples": ";".join(f"{s:.4f}" for s in samples[:5]),
                        "ratio_to_embree": speed / embree_speed, "hit_rate": rng.random(),
                        "agree_hit": agree_hit, "agree_prim": "" if occluded else 0.9995,
                        "prim_ties": 0, "t_relerr_max": "" if occluded else 1e-6,
                        "t_relerr_p999": "" if occluded else 1e-7, "disagreements": 3})
    return rows


def accuracy_rows():
    rng = random.Random(7)
    rows = [{"scene": scene, "rayset": rayset, "backend": backend, "rays": 4096,
             "false_miss": 0 if backend == "embree" else rng.choice([0, 1e-4, 3e-3]),
             "false_hit": rng.choice([0, 2e-4]),
             "wrong_prim": "" if rayset == "shadow" else rng.choice([0, 5e-4]),
             "mrays_s": rng.uniform(1, 20)}
            for scene in SCENES for rayset in RAYSETS for backend in BACKENDS]
    # Two backends on the same spot: their labels must be placed apart (and placing them end).
    rows[2].update({k: rows[1][k] for k in ("false_miss", "false_hit", "wrong_prim", "mrays_s")})
    return rows


def must_hit_rows():
    """The current schema: a `leaks` column, filled on a must-hit ray set of a closed mesh."""
    rows = [dict(r, leaks="") for r in results_rows() if r["rayset"] == "primary"]
    for backend, leaks in zip(BACKENDS, (60408, 35103, 0)):
        rows.append(dict(rows[0], scene="sphere", rayset="vertex-aimed", backend=backend,
                         leaks=leaks, agree_hit=1 - leaks / 8192))
    return rows


def write_csv(path, rows, columns):
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)


def run_report(*args, cwd=None):
    return subprocess.run([REPORT, *args], capture_output=True, text=True, cwd=cwd, timeout=60)


def image_links(markdown):
    return re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", markdown)


def table_pairs(markdown):
    """(scene, backend, threads) of every Markdown table row after the tables' heading."""
    tables = markdown.split("## Tables", 1)[1]
    pairs = set()
    for line in tables.splitlines():
        cells = [c.strip().replace("\\|", "|") for c in line.strip().strip("|").split(" | ")]
        if line.startswith("|") and len(cells) >= 3 and cells[2].isdigit():
            pairs.add((cells[0], cells[1], int(cells[2])))
    return pairs


class ReportTestCase(unittest.TestCase):
    """One report per input shape, made once: rendering dominates the test's time."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.dir = cls.tmp.name
        write_csv(cls.path("run.csv"), results_rows(), COLUMNS)
        with open(cls.path("run.meta.toml"), "w") as f:
            f.write(META)
        write_csv(cls.path("threads.csv"), results_rows((1, 2), seed=2), COLUMNS)
        write_csv(cls.path("accuracy.csv"), accuracy_rows(), list(accuracy_rows()[0]))
        # A relative path from the CSV's folder: the default out dir and any working directory.
        cls.plain = run_report("run.csv", cwd=cls.dir)
        cls.threads = run_report(cls.path("threads.csv"), "--out", cls.path("threads-out"))
        write_csv(cls.path("must-hit.csv"), must_hit_rows(), COLUMNS + ["leaks"])
        cls.must_hit = run_report(cls.path("must-hit.csv"), "--out", cls.path("must-hit-out"))
        cls.accuracy = run_report(cls.path("run.csv"), "--out", cls.path("acc-out"),
                                  "--accuracy", cls.path("accuracy.csv"), "--title", "My title")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    @classmethod
    def path(cls, *names):
        return os.path.join(cls.dir, *names)

    def read_report(self, out_dir):
        with open(os.path.join(out_dir, "report.md"), encoding="utf-8") as f:
            return f.read()

    def assertGoodReport(self, result, out_dir):
        """Exit 0, report.md, every linked PNG a real image, every PNG linked, no leftovers."""
        self.assertEqual(result.returncode, 0, result.stderr)
        markdown = self.read_report(out_dir)
        links = image_links(markdown)
        self.assertTrue(links, "no images linked")
        for link in links:
            self.assertFalse(os.path.isabs(link), link)
            png = os.path.join(out_dir, link)
            self.assertTrue(os.path.isfile(png), link)
            with open(png, "rb") as f:
                self.assertEqual(f.read(8), PNG_MAGIC, link)
            self.assertGreater(os.path.getsize(png), MIN_PNG_BYTES, link)
        self.assertEqual(sorted(n for n in os.listdir(out_dir) if n != "report.md"),
                         sorted(links), "files in the folder other than report.md and its PNGs")
        return markdown, links

    def test_default_out_dir_and_relative_path(self):
        out = self.path("run-report")
        self.assertGoodReport(self.plain, out)

    def test_tables_hold_every_scene_backend_pair(self):
        markdown, _ = self.assertGoodReport(self.plain, self.path("run-report"))
        expected = {(s, b, 1) for s in SCENES for b in BACKENDS}
        self.assertEqual(table_pairs(markdown), expected)
        for rayset in RAYSETS:
            self.assertIn(f"### {rayset} rays", markdown)

    def test_empty_fields_show_a_dash(self):
        markdown = self.read_report(self.path("run-report"))
        shadow = markdown.split("## Tables", 1)[1].split("### shadow rays", 1)[1]
        rows = [line for line in shadow.splitlines() if line.startswith("| bunny")]
        self.assertTrue(rows)
        for line in rows:
            agree_prim = line.strip("|").split(" | ")[7].strip()
            self.assertEqual(agree_prim, "\u2013", line)

    def test_plots_per_rayset_and_fallback_pareto(self):
        _, links = self.assertGoodReport(self.plain, self.path("run-report"))
        for rayset in RAYSETS:
            self.assertIn(f"throughput-{rayset}.png", links)
            self.assertIn(f"ratio-{rayset}.png", links)
        self.assertEqual(sorted(l for l in links if l.startswith("pareto-")),
                         ["pareto-bunny.png", "pareto-proc_terrain_spheres.png"])
        self.assertIn("disagreement with Embree", self.read_report(self.path("run-report")))

    def test_run_section_from_meta(self):
        markdown = self.read_report(self.path("run-report"))
        run = markdown.split("## Run", 1)[1].split("\n## ", 1)[0]
        for text in ("2026-01-02", "Test CPU 9000", "GNU 12.2.0", "-O3 -march=native", "3.13.5",
                     "0123456789abcdef-dirty", "4,096", "5"):
            self.assertIn(text, run)

    def test_several_thread_counts(self):
        markdown, links = self.assertGoodReport(self.threads, self.path("threads-out"))
        for rayset in RAYSETS:
            for threads in (1, 2):
                self.assertIn(f"throughput-{rayset}-t{threads}.png", links)
                self.assertIn(f"ratio-{rayset}-t{threads}.png", links)
        expected = {(s, b, t) for s in SCENES for b in BACKENDS for t in (1, 2)}
        self.assertEqual(table_pairs(markdown), expected)
        self.assertIn("Metadata: none", markdown)

    def test_accuracy_file_gives_pareto_plots(self):
        markdown, links = self.assertGoodReport(self.accuracy, self.path("acc-out"))
        self.assertTrue(markdown.startswith("# My title\n"))
        self.assertEqual(sorted(l for l in links if l.startswith("pareto-")),
                         ["pareto-bunny.png", "pareto-proc_terrain_spheres.png"])
        self.assertIn("accuracy.csv", markdown)
        self.assertNotIn("disagreement with Embree, not an error", markdown)

    def test_must_hit_rayset_shows_leaks(self):
        markdown, links = self.assertGoodReport(self.must_hit, self.path("must-hit-out"))
        self.assertIn("pareto-sphere.png", links)
        self.assertIn("throughput-vertex-aimed.png", links)
        table = markdown.split("## Tables", 1)[1].split("### vertex-aimed rays", 1)[1]
        self.assertIn("| leaks |", table)
        self.assertIn("| 60,408 |", table)
        primary = markdown.split("## Tables", 1)[1].split("### vertex-aimed rays", 1)[0]
        self.assertNotIn("leaks |", primary)

    def test_help(self):
        result = run_report("--help")
        self.assertEqual(result.returncode, 0)
        self.assertIn("usage:", result.stdout)
        self.assertIn("--accuracy", result.stdout)


class BadInputTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        self.good = os.path.join(self.dir, "good.csv")
        write_csv(self.good, results_rows(), COLUMNS)

    def tearDown(self):
        self.tmp.cleanup()

    def write(self, name, text):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def assertBadInput(self, bad_file, *args):
        """Exit 2, one line `report: error: FILE: problem`, and no output folder."""
        out = os.path.join(self.dir, "out")
        result = run_report(*args, "--out", out)
        self.assertEqual(result.returncode, 2, result.stderr)
        lines = result.stderr.splitlines()
        self.assertEqual(len(lines), 1, result.stderr)
        self.assertTrue(lines[0].startswith(f"report: error: {bad_file}: "), lines[0])
        self.assertFalse(os.path.exists(out))
        self.assertEqual(sorted(os.listdir(self.dir)), sorted(self.inputs()))

    def inputs(self):
        return [n for n in os.listdir(self.dir) if n != "out"]

    def test_missing_file(self):
        missing = os.path.join(self.dir, "nope.csv")
        self.assertBadInput(missing, missing)

    def test_empty_file(self):
        empty = self.write("empty.csv", "")
        self.assertBadInput(empty, empty)

    def test_header_only(self):
        header = self.write("header.csv", ",".join(COLUMNS) + "\n")
        self.assertBadInput(header, header)

    def test_missing_columns(self):
        rows = results_rows()
        columns = [c for c in COLUMNS if c not in ("agree_prim", "mrays_s_max")]
        path = os.path.join(self.dir, "columns.csv")
        write_csv(path, [{c: r[c] for c in columns} for r in rows], columns)
        self.assertBadInput(path, path)

    def test_not_a_number(self):
        rows = results_rows()
        rows[1]["mrays_s"] = "fast"
        path = os.path.join(self.dir, "nan.csv")
        write_csv(path, rows, COLUMNS)
        self.assertBadInput(path, path)

    def test_bad_accuracy_file(self):
        bad = self.write("acc.csv", "scene,rayset,backend\nbunny,primary,embree\n")
        self.assertBadInput(bad, self.good, "--accuracy", bad)

    def test_default_out_dir_not_created(self):
        empty = self.write("empty.csv", "")
        result = run_report(empty)
        self.assertEqual(result.returncode, 2)
        self.assertFalse(os.path.exists(os.path.join(self.dir, "empty-report")))


if __name__ == "__main__":
    unittest.main()
