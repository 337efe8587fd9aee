"""What every command-line test shares: running raybench as a user would (a hang ends in
TimeoutExpired, a failure rather than a stuck test), a fresh folder per test, and the rule
for bad input: exit status 2 and one line on stderr, `raybench: error: WHERE: problem`, the
last line (progress lines may precede it).

ctest sets RAYBENCH (the binary) and the mesh folders (harness/tests/CMakeLists.txt).
"""
import csv
import os
import subprocess
import tempfile
import tomllib
import unittest

RAYBENCH = os.environ["RAYBENCH"]
MODELS = os.environ.get("RAYBENCH_ASSIMP_MODELS", "/usr/share/assimp/models")


def run(*args, env=None, timeout=300):
    """raybench with these arguments; `env` adds to the environment."""
    return subprocess.run([RAYBENCH, *args], capture_output=True, text=True, timeout=timeout,
                          env={**os.environ, **(env or {})})


def read_rows(path):
    """A CSV's rows as dicts, every field as text."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def read_meta(csv_path):
    """The .meta.toml beside a results CSV."""
    with open(csv_path[:-len(".csv")] + ".meta.toml", "rb") as f:
        return tomllib.load(f)


class CliTestCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def path(self, *names):
        return os.path.join(self.dir, *names)

    def assertBadInput(self, result, *fragments):
        """Exit 2 and one error line on stderr, the last, naming each fragment; returns that line."""
        self.assertEqual(result.returncode, 2, result.stderr)
        lines = result.stderr.strip().splitlines()
        errors = [line for line in lines if line.startswith("raybench: error: ")]
        self.assertEqual(len(errors), 1, result.stderr)
        self.assertEqual(errors[0], lines[-1], result.stderr)
        for fragment in fragments:
            self.assertIn(fragment, errors[0])
        return errors[0]
