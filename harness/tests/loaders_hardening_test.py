"""Loading a scene cannot take raybench down (issue 28): a mesh that crashes or
hangs assimp, a malformed PLY, coordinates whose box areas overflow float,
a FIFO or a directory given as a mesh: each is exit status 2 with one line on
stderr naming the file (or the manifest's scene), never a crash or a hang.

Run through ctest (harness/tests/CMakeLists.txt sets RAYBENCH and the mesh folders).
"""
import os
import subprocess
import tempfile
import unittest

RAYBENCH = os.environ["RAYBENCH"]
MODELS = os.environ.get("RAYBENCH_ASSIMP_MODELS", "/usr/share/assimp/models")
WUSON = os.path.join(MODELS, "PLY", "Wuson.ply")

# The ASCII PLY of a unit square: its header and its vertex lines.
SQUARE_HEADER = (b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                 b"element face 2\nproperty list uchar int vertex_indices\nend_header\n")
SQUARE_VERTICES = b"0 0 0\n1 0 0\n1 1 0\n0 1 0\n"


def run(*args, env=None):
    # A hang would end here with TimeoutExpired: a failure, not a stuck test.
    return subprocess.run([RAYBENCH, *args], capture_output=True, text=True, timeout=120,
                          env={**os.environ, **(env or {})})


class LoadersTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def path(self, *names):
        return os.path.join(self.dir, *names)

    def write(self, name, data):
        with open(self.path(name), "wb") as f:
            f.write(data)
        return self.path(name)

    def load(self, scene, env=None, suite=None):
        """Loads a scene as `raybench rays` does (and makes 16 rays from it)."""
        args = ["rays", "--scene", scene, "--kind", "primary", "-n", "16", "-o", self.path("rays.npy")]
        if suite:
            args += ["--suite", suite]
        return run(*args, env=env)

    def assertBadInput(self, result, *fragments):
        """Exit 2 and one error line on stderr, the last, naming each fragment (progress lines may precede it)."""
        self.assertEqual(result.returncode, 2, result.stderr)
        lines = result.stderr.strip().splitlines()
        errors = [line for line in lines if line.startswith("raybench: error: ")]
        self.assertEqual(len(errors), 1, result.stderr)
        self.assertEqual(errors[0], lines[-1], result.stderr)
        for fragment in fragments:
            self.assertIn(fragment, errors[0])
        self.assertFalse(os.path.exists(self.path("rays.npy")))


class MeshesThatCrashAssimp(LoadersTestCase):
    def assertOnlyTheErrorLine(self, result):
        """assimp's own "ai_assert failure" line comes inside the error line, not before it."""
        self.assertEqual(len(result.stderr.strip().splitlines()), 1, result.stderr)

    def test_a_ply_cut_mid_file_is_an_error_naming_the_file(self):
        cut = self.write("cut.ply", SQUARE_HEADER + b"0 0 0\n1 0 0\n1 1 0\n0 1")
        result = self.load(cut)
        self.assertBadInput(result, cut, "assimp crashed (SIGABRT)", "malformed or truncated", "ai_assert failure")
        self.assertOnlyTheErrorLine(result)

    def test_an_off_cut_mid_file_is_an_error_naming_the_file(self):
        # assimp-testmodels' OFF/Cube.off cut after 202 of its 298 bytes.
        cut = self.write("cut.off", b"OFF\n8 6 0\n-0.500000 -0.500000 0.500000\n0.500000 -0.500000 0.500000\n"
                                    b"-0.500000 0.500000 0.500000\n0.500000 0.500000 0.500000\n"
                                    b"-0.500000 0.500000 -0.500000\n0.500000 0.500000 -0.500000\n"
                                    b"-0.500000 -0.500000 -0.")
        result = self.load(cut)
        self.assertBadInput(result, cut, "assimp crashed (SIGABRT)")
        self.assertOnlyTheErrorLine(result)

    def test_face_indices_out_of_range_or_negative_are_errors_naming_the_file(self):
        beyond = self.write("beyond.ply", SQUARE_HEADER + SQUARE_VERTICES + b"3 0 1 2\n3 0 2 9\n")
        self.assertBadInput(self.load(beyond), beyond, "uses vertex 9", "has 4 vertices")
        negative = self.write("negative.ply", SQUARE_HEADER + SQUARE_VERTICES + b"3 0 1 2\n3 0 2 -1\n")
        self.assertBadInput(self.load(negative), negative, "uses vertex -1", "has 4 vertices")


class MeshesThatHangAssimp(LoadersTestCase):
    def test_ply_heads_without_end_header_are_refused_before_assimp_loops_on_them(self):
        for name, first_line in (("space", b"ply "), ("tab", b"ply\t"), ("upper", b"PLY")):
            with self.subTest(first_line=first_line):
                path = self.write(name + ".ply", first_line + b"\nformat ascii 1.0\nelement vertex 3\n")
                self.assertBadInput(self.load(path), path, "header never ends")

    def test_a_loader_still_running_at_its_deadline_is_killed_and_named(self):
        # Wuson.ply (915 kB of ASCII) takes assimp tens of milliseconds: far
        # beyond a 1 ms deadline, so the loading process is killed.
        result = self.load(WUSON, env={"RAYBENCH_LOAD_TIMEOUT": "0.001"})
        self.assertBadInput(result, WUSON, "did not finish reading it within 0.001 s", "RAYBENCH_LOAD_TIMEOUT")
        self.assertEqual(self.load(WUSON).returncode, 0)

    def test_a_load_timeout_that_is_not_a_positive_number_is_refused(self):
        self.assertBadInput(self.load(WUSON, env={"RAYBENCH_LOAD_TIMEOUT": "-1"}), "RAYBENCH_LOAD_TIMEOUT", "'-1'")


class FilesThatAreNotMeshes(LoadersTestCase):
    def test_a_fifo_is_refused_before_it_is_opened(self):
        fifo = self.path("mesh.ply")
        os.mkfifo(fifo)
        self.assertBadInput(self.load(fifo), fifo, "FIFO")

    def test_a_directory_is_refused(self):
        folder = self.path("meshes.obj")
        os.mkdir(folder)
        self.assertBadInput(self.load(folder), folder, "directory")


class HugeCoordinates(LoadersTestCase):
    """Box areas overflow float beyond about 3.7e18; the wide BVH's collapse crashed on such scenes."""

    def test_a_mesh_with_coordinates_of_1e19_is_refused_naming_the_file(self):
        mesh = self.write("huge.obj", b"v 1e19 0 0\nv -1e19 0 0\nv 0 1e19 0\nf 1 2 3\n")
        self.assertBadInput(self.load(mesh), mesh, "within +-1e18")

    def test_a_mesh_with_coordinates_of_3e38_is_refused_naming_the_file(self):
        mesh = self.write("huger.obj", b"v 3e38 0 0\nv -3e38 0 0\nv 0 -3e38 0\nf 1 2 3\n")
        self.assertBadInput(self.load(mesh), mesh, "within +-1e18")

    def test_a_manifest_scale_of_1e20_on_a_procedural_scene_is_refused_naming_the_scene(self):
        suite = self.write("suite.toml", b'[[scene]]\nname = "huge"\npath = "proc:sphere"\nscale = 1e20\n')
        self.assertBadInput(self.load("huge", suite=suite), "scene 'huge'", "proc:sphere", "within +-1e18")
        out = self.path("run.csv")
        result = run("run", "--suite", suite, "--out", out, "--rays-dir", self.path("rays"), "--rays", "1000",
                     "--backend", "bvh8", "--reps", "1")
        self.assertBadInput(result, "scene 'huge'", "within +-1e18")
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
