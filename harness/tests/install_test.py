"""raybench as an installed tool (docs/install.md), as a user meets it: `cmake --install` into a
temporary prefix, which is then moved (the package must not name where it was built or
installed first); examples/my-kernel copied out of the source tree as a user's own repository,
configured with only that prefix, built; its plugin run by the installed binary on real meshes
next to Embree; the installed binary's defaults naming neither the source nor the build tree;
and the CI recipe of examples/my-kernel/README.md: an unchanged candidate passes the gate, a
deliberately wrong one (MY_KERNEL_DROP_EVERY) fails it on accuracy.

ctest sets RAYBENCH_SOURCE_DIR, RAYBENCH_BINARY_DIR (the build tree to install from), RAYBENCH_CMAKE,
RAYBENCH_CMAKE_GENERATOR and the mesh folders (harness/tests/CMakeLists.txt).
"""
import glob
import json
import os
import shutil
import subprocess
import tempfile
import unittest

from cli_testing import read_rows

SOURCE_DIR = os.path.realpath(os.environ["RAYBENCH_SOURCE_DIR"])
BINARY_DIR = os.path.realpath(os.environ["RAYBENCH_BINARY_DIR"])
CMAKE = os.environ.get("RAYBENCH_CMAKE", "cmake")
GENERATOR = os.environ.get("RAYBENCH_CMAKE_GENERATOR", "")
MESHES = os.environ["RAYBENCH_SHARED_MESHES"]
AGREEMENT = 0.9999  # issue 30: hit/miss agreement with Embree on real meshes


def call(args, cwd=None, env=None, timeout=300):
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, **(env or {})})



class Installed:
    """One install and example build shared by the tests (building is the slow part)."""

    def __init__(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="raybench-install-")
        self.root = os.path.realpath(self.tmp.name)
        first = os.path.join(self.root, "first-prefix")
        result = call([CMAKE, "--install", BINARY_DIR, "--prefix", first])
        assert result.returncode == 0, result.stdout + result.stderr
        # Moved after installing: a relocatable package works from anywhere.
        self.prefix = os.path.join(self.root, "prefix")
        os.rename(first, self.prefix)
        self.raybench = os.path.join(self.prefix, "bin", "raybench")
        # The user's repository: a copy, so that nothing can lean on the source tree.
        self.repo = os.path.join(self.root, "my-kernel")
        shutil.copytree(os.path.join(SOURCE_DIR, "examples", "my-kernel"), self.repo)
        self.cache = os.path.join(self.root, "cache")  # XDG_CACHE_HOME of every run
        self.plugin = self.build_plugin("build")

    def build_plugin(self, name, *definitions):
        """Configures and builds the example in <repo>/<name>; the path of its my_kernel.so."""
        build = os.path.join(self.repo, name)
        args = [CMAKE, "-S", self.repo, "-B", build, f"-DCMAKE_PREFIX_PATH={self.prefix}",
                "-DCMAKE_BUILD_TYPE=Release", *definitions]
        if GENERATOR:
            args += ["-G", GENERATOR]
        result = call(args)
        assert result.returncode == 0, result.stdout + result.stderr
        result = call([CMAKE, "--build", build])
        assert result.returncode == 0, result.stdout + result.stderr
        return os.path.join(build, "my_kernel.so")

    def run(self, *args, cwd):
        return call([self.raybench, *args], cwd=cwd, env={"XDG_CACHE_HOME": self.cache}, timeout=600)


INSTALLED = None


def setUpModule():
    global INSTALLED
    INSTALLED = Installed()


def tearDownModule():
    INSTALLED.tmp.cleanup()


class InstallTest(unittest.TestCase):
    def setUp(self):
        self.cwd = tempfile.mkdtemp(dir=INSTALLED.root, prefix="cwd-")

    def assertNamesNoTree(self, text, what):
        for tree in (SOURCE_DIR, BINARY_DIR):
            self.assertNotIn(tree, text, f"{what} names {tree}")

    def test_the_prefix_holds_the_documented_layout(self):
        p = INSTALLED.prefix
        for name in ["bin/raybench", "include/raybench/plugin.h", "share/raybench/suites/procedural.toml",
                     "share/raybench/gate.toml", "lib/cmake/raybench/raybenchConfig.cmake",
                     "lib/cmake/raybench/raybenchConfigVersion.cmake", "lib/cmake/raybench/raybench_add_plugin.cmake"]:
            self.assertTrue(os.path.isfile(os.path.join(p, name)), name)
        with open(os.path.join(p, "include/raybench/plugin.h")) as a, \
                open(os.path.join(SOURCE_DIR, "plugin/include/raybench/plugin.h")) as b:
            self.assertEqual(a.read(), b.read())
        # Nothing test-only: the only executable is raybench.
        executables = [f for f in glob.glob(os.path.join(p, "**"), recursive=True)
                       if os.path.isfile(f) and os.access(f, os.X_OK)]
        self.assertEqual(executables, [INSTALLED.raybench])

    def test_the_package_names_no_build_or_install_path(self):
        for f in glob.glob(os.path.join(INSTALLED.prefix, "lib", "cmake", "**", "*"), recursive=True) + \
                glob.glob(os.path.join(INSTALLED.prefix, "share", "**", "*"), recursive=True):
            if os.path.isfile(f):
                with open(f) as text:
                    content = text.read()
                self.assertNamesNoTree(content, f)
                self.assertNotIn("first-prefix", content, f)  # where it was installed before the move
        # The example found the moved prefix's package, and only it.
        with open(os.path.join(INSTALLED.repo, "build", "CMakeCache.txt")) as cache:
            self.assertIn(f"raybench_DIR:PATH={INSTALLED.prefix}/lib/cmake/raybench", cache.read())

    def test_installed_defaults_name_neither_tree(self):
        help_text = ""
        for command in ["run", "rays", "trace", "kernels", "accuracy-kernels", "gate", "scenes"]:
            result = INSTALLED.run(command, "--help", cwd=self.cwd)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertNamesNoTree(result.stdout, f"raybench {command} --help")
            help_text += result.stdout
        share = os.path.join(INSTALLED.prefix, "share", "raybench")
        self.assertIn(f"--suite TEXT={share}/suites/procedural.toml", help_text)
        self.assertIn("--out TEXT=raybench-results.csv", help_text)
        self.assertIn(f"--rays-dir TEXT={INSTALLED.cache}/raybench/rays", help_text)
        self.assertIn(f"--config TEXT={share}/gate.toml", help_text)

    def test_a_run_with_defaults_writes_to_the_current_directory(self):
        result = INSTALLED.run("run", "--scene", "sphere", "--rayset", "primary,shared-edge-aimed", "--rays", "2000",
                               "--backend", "embree,bvh8", "--reps", "1", "--build-reps", "1", "--min-time", "0.01",
                               "--warmup", "0.01", cwd=self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = read_rows(os.path.join(self.cwd, "raybench-results.csv"))
        self.assertEqual({r["scene"] for r in rows}, {"sphere"})  # a scene of the installed procedural suite
        self.assertEqual(len(rows), 4)
        with open(os.path.join(self.cwd, "raybench-results.meta.toml")) as f:
            meta = f.read()
        self.assertIn(os.path.join(INSTALLED.prefix, "share/raybench/suites/procedural.toml"), meta)
        self.assertNamesNoTree(meta, "the metadata")
        self.assertIn("git_commit", meta)
        self.assertTrue(glob.glob(os.path.join(INSTALLED.cache, "raybench", "rays", "sphere.*.npy")))

    def test_the_example_plugin_agrees_with_embree_on_real_meshes(self):
        bunny, conference = os.path.join(MESHES, "bunny.ply"), os.path.join(MESHES, "conference.ply")
        backend = "plugin:" + INSTALLED.plugin
        result = INSTALLED.run("run", "--backend", "embree," + backend, "--scene", f"{bunny},{conference}",
                               "--rayset", "primary,diffuse,shadow,uniform", "--rays", "20000", "--reps", "1",
                               "--build-reps", "1", "--min-time", "0.01", "--warmup", "0.01", "--out", "run.csv",
                               cwd=self.cwd)
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = [r for r in read_rows(os.path.join(self.cwd, "run.csv")) if r["backend"] == backend]
        self.assertEqual(len(rows), 8)
        for r in rows:
            self.assertEqual(r["plugin"], "my_kernel")
            self.assertGreaterEqual(float(r["agree_hit"]), AGREEMENT, f"{r['scene']} {r['rayset']}")


class CiRecipeTest(unittest.TestCase):
    """examples/my-kernel/README.md's CI recipe: baseline and candidate plugins in one run, the
    baseline as the reference, then `raybench gate --current --candidate` with its JSON verdicts."""

    def recipe(self, candidate_dir, *definitions):
        # 3 rounds: too few for the signed-rank test to ever call a speed change, so the verdicts
        # are deterministic (accuracy only) however busy the machine is; the README's recipe and
        # the workflow use 9.
        cwd = tempfile.mkdtemp(dir=INSTALLED.root, prefix="ci-")
        base = "plugin:" + INSTALLED.plugin
        cand = "plugin:" + INSTALLED.build_plugin(candidate_dir, *definitions)
        result = INSTALLED.run("run", "--backend", f"{base},{cand}", "--reference", base,
                               "--scene", os.path.join(MESHES, "bunny.ply"), "--rayset", "primary,diffuse,shadow",
                               "--rays", "20000", "--reps", "3", "--build-reps", "1", "--min-time", "0.01",
                               "--warmup", "0.01", "--accuracy", "acc.csv", "--out", "run.csv", cwd=cwd)
        self.assertEqual(result.returncode, 0, result.stderr)
        gate = INSTALLED.run("gate", "--current", "run.csv", "--candidate", cand, "--accuracy", "acc.csv",
                             "--json", "verdicts.json", cwd=cwd)
        with open(os.path.join(cwd, "verdicts.json")) as f:
            verdicts = json.load(f)
        return gate, verdicts

    def test_an_unchanged_candidate_passes(self):
        gate, verdicts = self.recipe("same")
        self.assertEqual(gate.returncode, 0, gate.stdout + gate.stderr)
        self.assertEqual(verdicts["verdict"], "pass")
        self.assertEqual(verdicts["failures"], [])

    def test_a_candidate_that_drops_rays_fails_on_accuracy(self):
        gate, verdicts = self.recipe("broken", "-DMY_KERNEL_DROP_EVERY=97")
        self.assertEqual(gate.returncode, 1, gate.stdout + gate.stderr)
        self.assertEqual(verdicts["verdict"], "fail")
        self.assertTrue(verdicts["failures"])
        for failure in verdicts["failures"]:
            self.assertIn("plugin:", failure["backend"])
        checks = " ".join(f["check"] + " " + f["message"] for f in verdicts["failures"])
        self.assertRegex(checks, "agree|referee|false_miss|accuracy")


if __name__ == "__main__":
    unittest.main()
