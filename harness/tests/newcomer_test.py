"""The stumbles of a newcomer's first hour (issue 29), driven through the command
line as they were met: each test is one stumble, and checks that raybench now
says what happened instead of staying silent or writing a wrong result.

Run through ctest (harness/tests/CMakeLists.txt sets RAYBENCH and the mesh folders).
"""
import csv
import os
import shutil
import subprocess
import sys
import unittest

from cli_test import RAYBENCH, WUSON, CliTestCase, run

SCRIPTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts")
QUICK = ["--reps", "1", "--build-reps", "1", "--min-time", "0.01", "--warmup", "0"]


class NewcomerTestCase(CliTestCase):
    def manifest(self, text):
        path = self.path("suite.toml")
        with open(path, "w") as f:
            f.write(text)
        return path

    def run_suite(self, *args):
        return run("run", "--out", self.path("run.csv"), "--rays-dir", self.path("rays"), *QUICK, *args)


def table_rows(stdout, title):
    """The rows of the table that follows `title` in a run's stdout, each split into its columns."""
    lines = stdout.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(title))
    header = lines[start + 1].split()
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("  ") or not line.strip():
            break
        rows.append(line.split())
    return header, rows


class AccuracyVerdictsOnScreen(NewcomerTestCase):
    def test_an_accuracy_run_prints_the_referees_verdicts_per_backend_and_ray_set(self):
        suite = self.manifest('[defaults]\nrays = 3000\nbackends = ["embree", "bvh2:mt_seed", "reference"]\n'
                              '[[scene]]\nname = "tiny"\npath = "proc:tiny_triangles"\nraysets = ["tiny-triangles"]\n'
                              '[[scene]]\nname = "ball"\npath = "proc:sphere"\nraysets = ["diffuse"]\n')
        result = self.run_suite("--suite", suite, "--accuracy", self.path("accuracy.csv"))
        self.assertEqual(result.returncode, 0, result.stderr)
        by = {}
        for scene in ("tiny", "ball"):
            header, rows = table_rows(result.stdout, f"{scene}: the exact referee's verdicts")
            # "ulp p50" and "ulp max" are two words each in the header.
            self.assertEqual(header, ["rayset", "backend", "class", "rays", "hits", "ambig", "f_miss", "f_hit", "wrong",
                                      "self", "ulp", "p50", "ulp", "max"])
            by.update({(r[0], r[1]): dict(zip(["rayset", "backend", "class", "rays", "hits", "ambig", "f_miss", "f_hit",
                                               "wrong", "self", "ulp_p50", "ulp_max"], r)) for r in rows})
        self.assertEqual(len(by), 6)
        # The triangle seed's det < 1e-4 hides every tiny triangle the referee says is hit.
        seed = by[("tiny-triangles", "bvh2:mt_seed")]
        self.assertEqual(seed["class"], "epsilon")
        self.assertGreater(int(seed["hits"]), 0)
        self.assertEqual(seed["f_miss"], seed["hits"])
        self.assertEqual(by[("tiny-triangles", "reference")]["f_miss"], "0")
        # Self-hits are judged on secondary rays only: the triangle seed, without a
        # minimum t, hits the triangle a diffuse ray leaves from; Embree does not.
        self.assertEqual(by[("tiny-triangles", "embree")]["self"], "-")
        self.assertEqual(by[("diffuse", "embree")]["self"], "0")
        self.assertGreater(int(by[("diffuse", "bvh2:mt_seed")]["self"]), 0)
        # The screen agrees with the accuracy CSV.
        with open(self.path("accuracy.csv")) as f:
            csv_seed = next(r for r in csv.DictReader(f) if r["rayset"] == "tiny-triangles" and r["backend"] == "bvh2:mt_seed")
        self.assertEqual(int(seed["f_miss"]), round(float(csv_seed["false_miss"]) * int(csv_seed["rays"])))
        for line in result.stdout.splitlines():
            self.assertLessEqual(len(line), 120, line)

    def test_a_run_without_accuracy_prints_no_verdicts(self):
        result = self.run_suite("--scene", "proc:sphere", "--rayset", "primary", "--rays", "500")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertNotIn("referee", result.stdout)


class DuplicateSceneNames(NewcomerTestCase):
    def setUp(self):
        super().setUp()
        self.suite = self.manifest('[defaults]\nrays = 500\nraysets = ["primary"]\n'
                                   '[[scene]]\nname = "spider"\npath = "proc:sphere"\n')
        self.mesh = self.path("spider.ply")
        shutil.copy(WUSON, self.mesh)

    def test_a_suite_name_and_a_path_with_the_same_stem_are_refused_naming_both(self):
        result = self.run_suite("--suite", self.suite, "--scene", f"spider,{self.mesh}")
        self.assertBadInput(result, "--scene: spider and " + self.mesh, "both name the scene 'spider'",
                                f"--scene spider_2={self.mesh}")
        self.assertFalse(os.path.exists(self.path("run.csv")))

    def test_the_same_scene_twice_is_refused(self):
        self.assertBadInput(self.run_suite("--suite", self.suite, "--scene", "spider,spider"),
                                "spider and spider both name the scene 'spider'", "give each scene once")

    def test_a_path_scene_named_on_the_command_line_gets_its_own_rows(self):
        result = self.run_suite("--suite", self.suite, "--scene", f"spider,wuson_big={self.mesh}", "--backend", "embree")
        self.assertEqual(result.returncode, 0, result.stderr)
        with open(self.path("run.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(sorted(r["scene"] for r in rows), ["spider", "wuson_big"])
        self.assertTrue(all(float(r["ratio_to_embree"]) == 1.0 for r in rows))
        self.assertTrue(any(name.startswith("wuson_big.primary.") for name in os.listdir(self.path("rays"))))

    def test_a_name_given_on_the_command_line_obeys_the_scene_name_rule(self):
        result = self.run_suite("--suite", self.suite, "--scene", f"bad\\name={self.mesh}")
        self.assertBadInput(result, "is read as NAME=PATH", "must not contain '\\'")


class CameraThatSeesLittle(NewcomerTestCase):
    # The unit sphere seen from 10 units away, 16.7 degrees off the axis of a
    # 50-degree camera: about 5 % of the primary rays hit it.
    AWAY = '[[scene]]\nname = "ball"\npath = "proc:sphere"\ncamera = { position = [0.0, 0.0, 10.0], look_at = [3.0, 0.0, 0.0] }\n'
    FACING = '[[scene]]\nname = "facing"\npath = "proc:sphere"\ncamera = { position = [0.0, 0.0, 3.0], look_at = [0.0, 0.0, 0.0] }\n'

    def test_a_run_warns_in_its_progress_and_in_its_table(self):
        suite = self.manifest('[defaults]\nrays = 4000\nraysets = ["primary"]\nbackends = ["bvh2"]\n' + self.AWAY + self.FACING)
        result = self.run_suite("--suite", suite)
        self.assertEqual(result.returncode, 0, result.stderr)
        warning = "camera sees little of the scene: "
        progress = [line for line in result.stderr.splitlines() if warning in line]
        self.assertEqual(len(progress), 1, result.stderr)
        self.assertRegex(progress[0], r"camera sees little of the scene: \d\.\d % of primary rays hit; "
                                      r"check it with scripts/preview_camera ball --suite " + suite)
        table = result.stdout.split("\nfacing (")
        self.assertEqual(len(table), 2, result.stdout)
        self.assertIn("  warning: " + warning, table[0])  # under the ball's header
        self.assertNotIn("warning", table[1])             # the sphere seen face on fills most of the view


class PreviewCamera(NewcomerTestCase):
    def preview(self, *args):
        env = dict(os.environ, RAYBENCH=RAYBENCH)
        return subprocess.run([sys.executable, os.path.join(SCRIPTS, "preview_camera.py"), *args],
                              capture_output=True, text=True, timeout=300, env=env, cwd=self.dir)

    def test_scenes_bounds_prints_a_scenes_bounds_and_camera(self):
        suite = self.manifest(CameraThatSeesLittle.AWAY)
        result = run("scenes", "--suite", suite, "--bounds", "--scene", "ball,proc:sphere")
        self.assertEqual(result.returncode, 0, result.stderr)
        lines = result.stdout.splitlines()
        self.assertEqual(lines[0], "ball: 2208 triangles")
        self.assertRegex(lines[1], r"^  bounds \(-1, -1, -1\) - \(1, 1, 1\), size \(2, 2, 2\)$")
        self.assertEqual(lines[2], "  camera (the suite's) position (0, 0, 10) look_at (3, 0, 0) up (0, 1, 0) fov 50")
        self.assertEqual(lines[3], "sphere: 2208 triangles")
        self.assertIn("camera (default: frames the bounds from outside)", lines[5])

    def test_preview_takes_a_suite_and_prints_the_bounds_and_what_the_camera_sees(self):
        suite = self.manifest(CameraThatSeesLittle.AWAY)
        result = self.preview("ball", "ball.png", "64", "--suite", suite)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("ball: 2208 triangles", result.stdout)
        self.assertIn("bounds (-1, -1, -1) - (1, 1, 1)", result.stdout)
        self.assertRegex(result.stdout, r"ball.png: \d\.\d% of primary rays hit")
        self.assertIn("warning: the camera sees little of the scene", result.stdout)
        with open(self.path("ball.png"), "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def test_a_scene_name_not_in_the_default_suite_needs_its_suite(self):
        self.assertNotEqual(self.preview("ball", "ball.png", "64").returncode, 0)


if __name__ == "__main__":
    unittest.main()
