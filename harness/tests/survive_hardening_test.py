"""Results survive (issue 28): every finished scene's rows are on disk while a run goes on; SIGINT and
SIGTERM remove the temporary files, say where the partial results are and exit 130 / 143; a failure in
a later scene keeps the earlier rows; the kernel benchmark leaves no *.tmp.gbench behind.

Run through ctest (harness/tests/CMakeLists.txt sets RAYBENCH).
"""
import glob
import os
import signal
import subprocess
import time
import unittest

import cli_testing
from cli_testing import RAYBENCH, CliTestCase, read_meta, read_rows

# A closed cube, 12 triangles: the run's third scene, a mesh file.
CUBE_OBJ = """v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 4 7 3
f 4 8 7
f 1 5 8
f 1 8 4
f 2 3 7
f 2 7 6
"""
SCENES = ["sphere", "terrain", "cube"]


def run(*args):
    return cli_testing.run(*args, timeout=600)




class SurviveTestCase(CliTestCase):
    def setUp(self):
        super().setUp()
        with open(self.path("cube.obj"), "w") as f:
            f.write(CUBE_OBJ)

    def write_suite(self, repetitions, min_time=0.01):
        """Three small scenes; with 25 repetitions of 0.04 s each takes seconds, so a signal lands mid-run."""
        suite = self.path("suite.toml")
        with open(suite, "w") as f:
            f.write(f'[defaults]\nrays = 2000\nrepetitions = {repetitions}\nbuild_repetitions = 1\nmin_time = {min_time}\n'
                    'warmup = 0.0\nraysets = ["primary"]\nbackends = ["embree", "bvh2"]\n'
                    '[[scene]]\nname = "sphere"\npath = "proc:sphere"\n'
                    '[[scene]]\nname = "terrain"\npath = "proc:terrain_spheres_small"\n'
                    '[[scene]]\nname = "cube"\npath = "cube.obj"\n')
        return suite

    def signal_when(self, process, ready, sig, what):
        """Sends `sig` to `process` once ready() holds (polled; at most 300 s) and returns its exit status."""
        try:
            deadline = time.monotonic() + 300
            while not ready():
                self.assertIsNone(process.poll(), f"the process ended before {what}")
                self.assertLess(time.monotonic(), deadline, f"not {what} after 300 s")
                time.sleep(0.02)
            process.send_signal(sig)
            return process.wait(timeout=60)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()

    def assertNoTemporaryFiles(self):
        left = [p for pattern in ("*.tmp.*", "*.probe.*", "*.tmp.gbench")
                for p in glob.glob(os.path.join(self.dir, "**", pattern), recursive=True)]
        self.assertEqual(left, [])

    def assertPartialResults(self, out, finished):
        """`out` holds exactly the rows of the first `finished` scenes, marked partial, each scene's ratios final."""
        rows = read_rows(out)
        self.assertEqual(sorted({r["scene"] for r in rows}), sorted(SCENES[:finished]))
        self.assertEqual(len(rows), 2 * finished)  # one ray set x two backends per scene
        for row in rows:
            self.assertGreater(float(row["mrays_s"]), 0)
            self.assertGreater(float(row["ratio_to_embree"]), 0)
        meta = read_meta(out)
        self.assertEqual(meta["status"], "partial")
        self.assertEqual(meta["progress"], f"{finished} of 3 scenes")
        self.assertEqual(meta["scenes"], ",".join(SCENES))


class Signals(SurviveTestCase):
    def interrupt_after_first_scene(self, sig):
        """Starts a three-scene run, waits until the first scene's rows are on disk, sends `sig`."""
        out = self.path("results", "run.csv")
        with open(self.path("stderr.txt"), "w") as err, open(self.path("stdout.txt"), "w") as stdout:
            process = subprocess.Popen([RAYBENCH, "run", "--suite", self.write_suite(repetitions=25, min_time=0.04), "--out", out,
                                        "--rays-dir", self.path("rays")], stdout=stdout, stderr=err)
            returncode = self.signal_when(process, lambda: os.path.exists(out) and read_rows(out), sig,
                                          "the first scene's rows written")
        with open(self.path("stderr.txt")) as f:
            return out, returncode, f.read().strip().splitlines()

    def check_interrupted_run(self, sig, name, status):
        out, returncode, stderr = self.interrupt_after_first_scene(sig)
        self.assertEqual(returncode, status, stderr[-5:])
        finished = int(read_meta(out)["progress"].split()[0])
        self.assertIn(finished, (1, 2))  # the signal came after scene 1's rows, before the run's end
        self.assertEqual(stderr[-1], f"raybench: interrupted by {name}: partial results ({finished} of 3 scenes) in {out}")
        self.assertPartialResults(out, finished)
        self.assertNoTemporaryFiles()
        # The finished rows are a results file raybench reads back.
        compared = run("compare", out, out)
        self.assertEqual(compared.returncode, 0, compared.stderr)
        self.assertIn("sphere", compared.stdout)

    def test_sigint_keeps_finished_scenes_removes_temporary_files_and_exits_130(self):
        self.check_interrupted_run(signal.SIGINT, "SIGINT", 130)

    def test_sigterm_keeps_finished_scenes_removes_temporary_files_and_exits_143(self):
        self.check_interrupted_run(signal.SIGTERM, "SIGTERM", 143)


class FailureInALaterScene(SurviveTestCase):
    def test_a_complete_run_is_marked_complete(self):
        out = self.path("run.csv")
        result = run("run", "--suite", self.write_suite(repetitions=1), "--out", out, "--rays-dir", self.path("rays"))
        self.assertEqual(result.returncode, 0, result.stderr)
        meta = read_meta(out)
        self.assertEqual((meta["status"], meta["progress"]), ("complete", "3 of 3 scenes"))
        rows = read_rows(out)
        self.assertEqual(len(rows), 6)
        for row in rows:
            if row["backend"] == "embree":
                self.assertEqual(float(row["ratio_to_embree"]), 1.0)
        self.assertNoTemporaryFiles()

    def test_a_failure_in_a_later_scene_keeps_the_earlier_rows_and_says_where(self):
        suite = self.write_suite(repetitions=1)
        rays = self.path("rays")
        # A real failure late in the run: the second scene's stored ray file
        # cannot be written (a directory stands where it goes).
        made = run("run", "--suite", suite, "--scene", "terrain", "--out", self.path("first.csv"), "--rays-dir", rays)
        self.assertEqual(made.returncode, 0, made.stderr)
        terrain_rays = glob.glob(os.path.join(rays, "terrain.*.npy"))
        self.assertEqual(len(terrain_rays), 1, os.listdir(rays))
        os.remove(terrain_rays[0])
        os.mkdir(terrain_rays[0])

        out, accuracy = self.path("run.csv"), self.path("accuracy.csv")
        result = run("run", "--suite", suite, "--out", out, "--rays-dir", rays, "--accuracy", accuracy)
        self.assertEqual(result.returncode, 2, result.stderr)
        lines = result.stderr.strip().splitlines()
        self.assertTrue(lines[-1].startswith("raybench: error: "), lines[-1])
        self.assertIn(terrain_rays[0], lines[-1])
        self.assertIn("(in scene 2 of 3)", lines[-1])
        self.assertIn(f"partial results (1 of 3 scenes) in {out} and {accuracy}", lines[-1])
        self.assertPartialResults(out, 1)
        accuracy_rows = read_rows(accuracy)
        self.assertEqual({(r["scene"], r["backend"]) for r in accuracy_rows}, {("sphere", "embree"), ("sphere", "bvh2")})
        self.assertEqual((read_meta(accuracy)["status"], read_meta(accuracy)["progress"]), ("partial", "1 of 3 scenes"))
        self.assertNoTemporaryFiles()


class KernelBenchmarkTemporaryFiles(SurviveTestCase):
    def test_a_json_path_that_is_a_directory_fails_before_timing_and_leaves_no_temporary_file(self):
        os.mkdir(self.path("k.json"))
        result = run("kernels", "--reps", "1", "--min-time", "0.001", "--pairs", "64", "--out", self.path("k.csv"),
                     "--json", self.path("k.json"))
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertTrue(result.stderr.strip().splitlines()[-1].startswith("raybench: error: "), result.stderr)
        self.assertIn("k.json", result.stderr.strip().splitlines()[-1])
        self.assertNotIn("[1/", result.stderr)  # nothing was timed
        self.assertFalse(os.path.exists(self.path("k.csv")))
        self.assertNoTemporaryFiles()

    def test_a_json_path_under_a_file_fails_and_leaves_no_temporary_file(self):
        open(self.path("blocker"), "w").close()
        result = run("kernels", "--reps", "1", "--min-time", "0.001", "--pairs", "64", "--out", self.path("k.csv"),
                     "--json", self.path("blocker", "k.json"))
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertFalse(os.path.exists(self.path("k.csv")))
        self.assertNoTemporaryFiles()

    def test_killed_kernels_leave_no_temporary_file(self):
        js = self.path("k.json")
        with open(self.path("stderr.txt"), "w") as err:
            process = subprocess.Popen([RAYBENCH, "kernels", "--reps", "1000", "--min-time", "0.01", "--pairs", "64",
                                        "--out", self.path("k.csv"), "--json", js], stdout=subprocess.DEVNULL, stderr=err)
            returncode = self.signal_when(process, lambda: os.path.exists(js + ".tmp.gbench"), signal.SIGTERM,
                                          "Google Benchmark's output opened")
        with open(self.path("stderr.txt")) as f:
            last = f.read().strip().splitlines()[-1]
        self.assertEqual(returncode, 143, last)
        self.assertEqual(last, "raybench: interrupted by SIGTERM: no results written")
        self.assertFalse(os.path.exists(js))
        self.assertFalse(os.path.exists(self.path("k.csv")))
        self.assertNoTemporaryFiles()


if __name__ == "__main__":
    unittest.main()
