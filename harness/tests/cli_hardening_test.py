"""Issue 28, the command line and the manifest: every numeric input judged at the
boundary by one set of rules, cameras that define a view, scene names that stay
file names and CSV fields, outputs that never overwrite each other or a device,
missing scenes that are errors, .npy headers read exactly, and Embree's
occlusion answer for empty intervals. Each case is the issue's exact input;
bad input gives one line on stderr naming the flag or the file and key, exit
status 2, and no result file.

Run through ctest (harness/tests/CMakeLists.txt sets RAYBENCH and the mesh folders).
"""
import os
import stat
import subprocess
import tempfile
import unittest

import numpy as np

RAYBENCH = os.environ["RAYBENCH"]
SCENE = "proc:terrain_spheres_small"
BACKENDS = ("embree", "bvh2", "bvh8", "bvh4", "reference")


def run(*args, timeout=300):
    return subprocess.run([RAYBENCH, *args], capture_output=True, text=True, timeout=timeout)


class HardeningTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def path(self, *names):
        return os.path.join(self.dir, *names)

    def assertBadInput(self, result, *fragments):
        """Exit 2 and one error line on stderr, the last, naming each fragment (progress lines may precede it)."""
        self.assertEqual(result.returncode, 2, result.stderr)
        lines = result.stderr.strip().splitlines()
        errors = [line for line in lines if line.startswith("raybench: error: ")]
        self.assertEqual(len(errors), 1, result.stderr)
        self.assertEqual(errors[0], lines[-1], result.stderr)
        for fragment in fragments:
            self.assertIn(fragment, errors[0])
        return errors[0]

    def manifest(self, text, name="suite.toml"):
        path = self.path(name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def run_suite(self, suite, *args):
        """A run that must not get far: tiny settings, its outputs in the temporary folder."""
        return run("run", "--suite", suite, "--out", self.path("out.csv"), "--rays-dir", self.path("rays"), *args)

    def assertNothingWritten(self):
        self.assertFalse(os.path.exists(self.path("out.csv")))
        self.assertFalse(os.path.exists(self.path("rays")))


SPHERE = '[[scene]]\nname = "sphere"\npath = "proc:sphere"\n'


class NumericFlags(HardeningTestCase):
    """The same rules as the manifest's, with the flag named and our own words (not CLI11's)."""

    def test_rays_0_is_refused_not_read_as_the_suite_default(self):
        self.assertBadInput(run("run", "--rays", "0", "--out", self.path("out.csv")),
                            "--rays: must be an integer from 1 to 268435456, got 0")
        self.assertFalse(os.path.exists(self.path("out.csv")))

    def test_negative_rays_fail_at_once_before_any_scene_is_loaded(self):
        result = run("run", "--rays", "-5", "--out", self.path("out.csv"))
        self.assertBadInput(result, "--rays: must be an integer from 1 to 268435456, got -5")
        self.assertNotIn("loading", result.stderr)

    def test_thread_counts_do_not_wrap(self):
        self.assertBadInput(run("run", "--threads", "1,3000000000", "--out", self.path("out.csv")),
                            "--threads: must be an integer from 1 to 1024, got 3000000000")
        self.assertBadInput(run("trace", "--scene", SCENE, "--rays", "r.npy", "-o", self.path("h.npy"), "-t", "0"),
                            "--threads: must be an integer from 1 to 1024, got 0")

    def test_min_time_and_warmup_are_finite_seconds(self):
        for value in ("0", "-1", "nan", "inf"):
            with self.subTest(min_time=value):
                self.assertBadInput(run("run", "--min-time", value, "--out", self.path("out.csv")),
                                    f"--min-time: must be a finite number of seconds in (0, 3600], got {value}")
        for value in ("-1", "nan", "inf"):
            with self.subTest(warmup=value):
                self.assertBadInput(run("run", "--warmup", value, "--out", self.path("out.csv")),
                                    f"--warmup: must be a finite number of seconds in [0, 3600], got {value}")
        self.assertBadInput(run("kernels", "--min-time", "nan", "--out", self.path("k.csv")),
                            "--min-time: must be a finite number of seconds in (0, 3600], got nan")

    def test_repetitions_are_at_least_1(self):
        self.assertBadInput(run("run", "--reps", "0", "--out", self.path("out.csv")), "--reps: must be an integer from 1 to 1000")
        self.assertBadInput(run("run", "--build-reps", "-3", "--out", self.path("out.csv")),
                            "--build-reps: must be an integer from 1 to 1000, got -3")
        self.assertBadInput(run("kernels", "--reps", "0", "--out", self.path("k.csv")), "--reps: must be an integer")

    def test_kernel_pairs_of_minus_1_do_not_wrap_to_2_to_the_64(self):
        result = run("kernels", "--pairs", "-1", "--out", self.path("k.csv"), "--json", "", timeout=60)
        self.assertBadInput(result, "--pairs: must be an integer from 8 to 16777216, got -1")
        self.assertFalse(os.path.exists(self.path("k.csv")))

    def test_range_errors_name_the_range_not_a_309_digit_number(self):
        for args, message in ((["accuracy-kernels", "--rays", "0"], "--rays: must be an integer from 1 to 16777216, got 0"),
                              (["accuracy-kernels", "--rays", "-1"], "--rays: must be an integer from 1 to 16777216, got -1"),
                              (["rays", "--scene", SCENE, "-n", "-5"],
                               "--count: must be an integer from 1 to 268435456, got -5"),
                              (["compare", "a.csv", "b.csv", "--alpha", "nan"],
                               "--alpha: must be a significance level in (0, 1), got nan"),
                              (["compare", "a.csv", "b.csv", "--min-effect", "-1"],
                               "--min-effect: must be a relative change in [0, 10], got -1"),
                              (["run", "--seed", "-1"], "--seed: must be an integer from 0 to 18446744073709551615, got -1")):
            with self.subTest(args=args):
                error = self.assertBadInput(run(*args, "--out", self.path("never.csv")), message)
                self.assertNotRegex(error, r"\d{25}")
        self.assertFalse(os.path.exists(self.path("never.csv")))


class NumericManifestValues(HardeningTestCase):
    """A manifest's bad value names the manifest and the key, never a flag that was not given."""

    def test_every_bad_default_names_the_file_and_key(self):
        for line, key in (("threads = [3000000000]", "defaults.threads"),
                          ("min_time = 0", "defaults.min_time"),
                          ("min_time = -1.0", "defaults.min_time"),
                          ("min_time = nan", "defaults.min_time"),
                          ("warmup = -1.0", "defaults.warmup"),
                          ("warmup = nan", "defaults.warmup"),
                          ("warmup = inf", "defaults.warmup"),
                          ("repetitions = 0", "defaults.repetitions"),
                          ("build_repetitions = 0", "defaults.build_repetitions"),
                          ("rays = 0", "defaults.rays")):
            with self.subTest(line=line):
                suite = self.manifest(f"[defaults]\n{line}\n" + SPHERE)
                result = self.run_suite(suite)
                error = self.assertBadInput(result, f"{suite}: '{key}': must be")
                self.assertNotIn("--", error)
                self.assertNotIn("loading", result.stderr)
                self.assertNothingWritten()

    def test_a_flag_given_replaces_a_bad_manifest_value_only_by_being_judged_itself(self):
        suite = self.manifest("[defaults]\nrays = 100\n" + SPHERE)
        self.assertBadInput(self.run_suite(suite, "--rays", "0"), "--rays: must be an integer from 1")


class Cameras(HardeningTestCase):
    def test_a_camera_that_cannot_see_is_refused_naming_the_file_and_key(self):
        for camera, key, problem in (
                ("{ position = [nan, 0, 0], look_at = [0, 0, 0] }", "scene[0].camera.position", "finite"),
                ("{ position = [0, 0, inf], look_at = [0, 0, 0] }", "scene[0].camera.position", "finite"),
                ("{ position = [0, 0, 5], look_at = [0, 0, 0], up = [nan, 1, 0] }", "scene[0].camera.up", "finite"),
                ("{ position = [1, 2, 3], look_at = [1, 2, 3] }", "scene[0].camera.look_at", "looks nowhere"),
                ("{ position = [0, 5, 0], look_at = [0, 0, 0], up = [0, 1, 0] }", "scene[0].camera.up", "parallel")):
            with self.subTest(camera=camera):
                suite = self.manifest(f"{SPHERE}camera = {camera}\n")
                self.assertBadInput(self.run_suite(suite, "--rays", "100"), f"{suite}: '{key}'", problem)
                self.assertNothingWritten()

    def test_lights_and_inside_balls_are_finite(self):
        for line, key in (("light = [nan, 0, 0]", "scene[0].light"),
                          ("light = [0, inf, 0]", "scene[0].light"),
                          ("inside = { center = [0, 0, nan], radius = 0.5 }", "scene[0].inside.center"),
                          ("inside = { center = [0, 0, 0], radius = inf }", "scene[0].inside.radius")):
            with self.subTest(line=line):
                suite = self.manifest(f"{SPHERE}{line}\n")
                self.assertBadInput(self.run_suite(suite, "--rays", "100"), f"{suite}: '{key}'", "finite")


class SceneNames(HardeningTestCase):
    def test_a_name_with_dot_dot_slash_cannot_write_outside_the_rays_dir(self):
        suite = self.manifest('[[scene]]\nname = "../evil"\npath = "proc:sphere"\n')
        self.assertBadInput(self.run_suite(suite, "--rays", "100"), f"{suite}: 'scene[0].name'", "'/'")
        self.assertEqual(os.listdir(self.dir), ["suite.toml"])

    def test_a_name_with_a_newline_cannot_break_the_csv(self):
        suite = self.manifest('[[scene]]\nname = "two\\nlines"\npath = "proc:sphere"\n')
        self.assertBadInput(self.run_suite(suite, "--rays", "100"), f"{suite}: 'scene[0].name'", "control character")
        self.assertNothingWritten()

    def test_a_mesh_whose_file_stem_is_no_scene_name_is_refused_with_advice(self):
        mesh = self.path("two\nlines.obj")
        with open(mesh, "w") as f:
            f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        result = run("run", "--scene", mesh, "--rays", "100", "--out", self.path("out.csv"), "--rays-dir", self.path("rays"))
        self.assertBadInput(result, "--scene", "two\\x0alines.obj", "name the scene in a suite manifest")
        self.assertNothingWritten()


class OneLineErrors(HardeningTestCase):
    def test_a_newline_in_a_users_name_cannot_split_the_error_line(self):
        mesh = self.path("two\nlines.obj")
        self.assertBadInput(run("rays", "--scene", mesh, "-o", self.path("r.npy")), "two\\x0alines.obj", "no such file")
        self.assertBadInput(run("run", "--scene", "proc:sphere", "--backend", "bvh2\nx", "--rays", "100",
                                "--out", self.path("o.csv"), "--rays-dir", self.path("rays")), "bvh2\\x0ax")


class Outputs(HardeningTestCase):
    def run_tiny(self, *args):
        return run("run", "--scene", "proc:sphere", "--rayset", "uniform", "--backend", "bvh2", "--rays", "100",
                   "--reps", "1", "--build-reps", "1", "--min-time", "0.001", "--warmup", "0",
                   "--rays-dir", self.path("rays"), *args)

    def test_accuracy_equal_to_out_is_refused_in_every_spelling(self):
        os.mkdir(self.path("sub"))
        out = self.path("run.csv")
        spellings = (out, self.path("sub", "..", "run.csv"), self.path(".", "run.csv"), self.path("link.csv"))
        for accuracy in spellings[:3]:
            with self.subTest(accuracy=accuracy):
                self.assertBadInput(self.run_tiny("--out", out, "--accuracy", accuracy),
                                    f"--accuracy {accuracy} is the same file as --out {out}")
                self.assertFalse(os.path.exists(out))
        # A previous result, and a symbolic link to it: the same file too.
        with open(out, "w") as f:
            f.write("previous results\n")
        os.symlink(out, self.path("link.csv"))
        for accuracy in spellings:
            with self.subTest(accuracy=accuracy, existing=True):
                self.assertBadInput(self.run_tiny("--out", out, "--accuracy", accuracy),
                                    f"--accuracy {accuracy} is the same file as --out {out}")
                with open(out) as f:
                    self.assertEqual(f.read(), "previous results\n")

    def test_accuracy_and_out_metadata_files_must_not_collide(self):
        out = self.path("run.csv")
        self.assertBadInput(self.run_tiny("--out", out, "--accuracy", self.path("run")),
                            "the metadata of --accuracy", "is the same file as the metadata of --out")
        self.assertBadInput(self.run_tiny("--out", out, "--accuracy", self.path("run.meta.toml")),
                            "is the same file as the metadata of --out")
        self.assertFalse(os.path.exists(out))

    def test_separate_files_are_written(self):
        result = self.run_tiny("--out", self.path("run.csv"), "--accuracy", self.path("accuracy.csv"))
        self.assertEqual(result.returncode, 0, result.stderr)
        for name in ("run.csv", "run.meta.toml", "accuracy.csv", "accuracy.meta.toml"):
            self.assertTrue(os.path.exists(self.path(name)), name)

    def test_no_command_writes_its_results_over_a_device(self):
        rays = self.path("r.npy")
        np.save(rays, np.array([[0, 0, 5, 0, 0, 0, -1, np.inf]], dtype=np.float32))
        for name in ("a.csv", "b.csv"):
            open(self.path(name), "w").close()
        for args in (["run", "--scene", "proc:sphere", "--rays", "100", "--rays-dir", self.path("rays"), "--out"],
                     ["run", "--scene", "proc:sphere", "--rays", "100", "--rays-dir", self.path("rays"),
                      "--out", self.path("o.csv"), "--accuracy"],
                     ["rays", "--scene", "proc:sphere", "-n", "10", "-o"],
                     ["trace", "--scene", "proc:sphere", "--rays", rays, "-o"],
                     ["kernels", "--json", "", "--out"],
                     ["kernels", "--out", self.path("k.csv"), "--json"],
                     ["accuracy-kernels", "--out"],
                     ["compare", self.path("a.csv"), self.path("b.csv"), "--out"]):
            with self.subTest(args=args):
                self.assertBadInput(run(*args, "/dev/null"), "/dev/null", "is a character device")
                self.assertTrue(stat.S_ISCHR(os.stat("/dev/null").st_mode))

    def test_an_empty_output_name_is_refused_before_the_run_not_after(self):
        for args in (["run", "--scene", "proc:sphere", "--rays", "100", "--rays-dir", self.path("rays"), "--out", ""],
                     ["run", "--scene", "proc:sphere", "--rays", "100", "--out", self.path("o.csv"), "--rays-dir", ""],
                     ["rays", "--scene", "proc:sphere", "-n", "10", "-o", ""],
                     ["kernels", "--json", "", "--out", ""]):
            with self.subTest(args=args):
                result = run(*args)
                self.assertBadInput(result, "must name a")
                self.assertNotIn("loading", result.stderr)

    def test_an_output_is_never_one_of_the_inputs(self):
        rays = self.path("r.npy")
        np.save(rays, np.array([[0, 0, 5, 0, 0, 0, -1, np.inf]], dtype=np.float32))
        self.assertBadInput(run("trace", "--scene", "proc:sphere", "--rays", rays, "-o", rays),
                            f"--out {rays} is the same file as the input --rays {rays}")
        self.assertEqual(np.load(rays).shape, (1, 8))
        mesh = self.path("tri.obj")
        with open(mesh, "w") as f:
            f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
        self.assertBadInput(run("trace", "--scene", mesh, "--rays", rays, "-o", mesh),
                            f"--out {mesh} is the same file as the input --scene {mesh}")
        self.assertBadInput(run("rays", "--scene", mesh, "-n", "10", "-o", mesh), "is the same file as the input --scene")
        with open(mesh) as f:
            self.assertTrue(f.read().startswith("v 0 0 0"))

    def test_an_unwritable_out_is_named_as_given_not_as_an_internal_probe_file(self):
        blocker = self.path("file")
        open(blocker, "w").close()
        out = os.path.join(blocker, "run.csv")
        error = self.assertBadInput(self.run_tiny("--out", out), out)
        self.assertNotIn(".probe.", error)


class MissingScenes(HardeningTestCase):
    def test_a_missing_scene_that_is_not_optional_is_an_error_before_the_run(self):
        suite = self.manifest(SPHERE + '[[scene]]\nname = "needed"\npath = "absent.ply"\n')
        result = self.run_suite(suite, "--rays", "100")
        self.assertBadInput(result, suite, "scene 'needed'", "not found")
        self.assertNotIn("loading", result.stderr)
        self.assertNothingWritten()

    def test_a_missing_optional_scene_is_skipped_with_a_note(self):
        suite = self.manifest(SPHERE + '[[scene]]\nname = "extra"\npath = "absent.ply"\noptional = true\n')
        result = self.run_suite(suite, "--rays", "100", "--rayset", "uniform", "--backend", "bvh2", "--reps", "1",
                                "--build-reps", "1", "--min-time", "0.001", "--warmup", "0")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("skipping scene 'extra'", result.stderr)


def npy_with_shape(path, shape, body_bytes):
    """A version 1.0 .npy file whose header says `shape` (written as given), with body_bytes zero bytes."""
    header = "{'descr': '<f4', 'fortran_order': False, 'shape': " + shape + ", }"
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header.encode() + bytes(body_bytes))
    return path


class RayFiles(HardeningTestCase):
    def trace(self, rays, *args):
        return run("trace", "--scene", "proc:sphere", "--rays", rays, "-o", self.path("hits.npy"), *args, timeout=60)

    def test_a_negative_dimension_is_refused_not_read_as_positive(self):
        rays = npy_with_shape(self.path("neg.npy"), "(-16, 8)", 16 * 32)
        self.assertBadInput(self.trace(rays), rays, "'shape'", "dimension 0 is negative")
        self.assertFalse(os.path.exists(self.path("hits.npy")))

    def test_overflowing_dimensions_say_so(self):
        for shape, problem in (("(99999999999999999999999, 8)", "is too large"),
                               ("(18446744073709551615, 8)", "more than the file's"),
                               ("(4611686018427387904, 8)", "more than the file's")):
            with self.subTest(shape=shape):
                rays = npy_with_shape(self.path("huge.npy"), shape, 64)
                error = self.assertBadInput(self.trace(rays), rays, problem)
                self.assertNotIn("stoull", error)
                self.assertNotIn("max_size", error)

    def test_a_fifo_is_refused_not_waited_on(self):
        fifo = self.path("fifo")
        os.mkfifo(fifo)
        self.assertBadInput(self.trace(fifo), fifo, "FIFO")
        self.assertBadInput(run("run", "--suite", fifo, "--out", self.path("o.csv"), timeout=60), fifo, "FIFO")
        self.assertBadInput(run("scenes", "--suite", fifo, timeout=60), fifo, "FIFO")
        self.assertBadInput(run("compare", fifo, fifo, timeout=60), fifo, "FIFO")
        self.assertBadInput(run("gate", "--baseline", fifo, "--current", fifo, "--config", fifo, timeout=60), fifo, "FIFO")


class EmptyIntervals(HardeningTestCase):
    """A ray whose interval (max(tnear, 0), tfar] is empty hits nothing and is occluded by nothing, in every backend.
    Issue 28: embree --occluded reported tfar = -inf as occluded."""

    def test_every_backend_answers_miss_and_not_occluded(self):
        # Straight down at the unit sphere from z = 5: the line crosses it at t = 4 and t = 6.
        rays = np.array([[0, 0, 5, 0, 0, 0, -1, -np.inf],   # tfar = -inf
                         [0, 0, 5, 0, 0, 0, -1, -1],        # tfar = -1
                         [0, 0, 5, 7, 0, 0, -1, 3],         # tfar < tnear
                         [0, 0, 5, 0, 0, 0, -1, np.inf]],   # a ray that hits, as a control
                        dtype=np.float32)
        path = self.path("empty.npy")
        np.save(path, rays)
        for backend in BACKENDS:
            with self.subTest(backend=backend):
                occluded = self.path(f"occ_{backend}.npy")
                result = run("trace", "--scene", "proc:sphere", "--rays", path, "-b", backend, "--occluded", "-o", occluded)
                self.assertEqual(result.returncode, 0, result.stderr)
                np.testing.assert_array_equal(np.load(occluded)[:, 0], [0, 0, 0, 1])
                hits = self.path(f"hits_{backend}.npy")
                result = run("trace", "--scene", "proc:sphere", "--rays", path, "-b", backend, "-o", hits)
                self.assertEqual(result.returncode, 0, result.stderr)
                h = np.load(hits)
                np.testing.assert_array_equal(h[:3, 1], -1)  # prim -1 and t = inf: a miss
                self.assertTrue(np.isinf(h[:3, 0]).all())
                self.assertGreaterEqual(h[3, 1], 0)


if __name__ == "__main__":
    unittest.main()
