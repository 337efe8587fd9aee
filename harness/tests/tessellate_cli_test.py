"""Issue 31, the tessellation study from the command line: --tessellate and a manifest's
`tessellate` are judged before anything runs (one line naming the flag or the file and key),
`--tessellate none` turns the study off, a scene without analytic primitives is traced as itself
only (representation `triangles`), and the run's resolutions are in its metadata. On a scene with
analytic primitives (proc:analytic_mix, once scenes can hold them) each stand-in is traced by
every backend with the scene's rays and judged by its referee.

Run through ctest (harness/tests/CMakeLists.txt sets RAYBENCH).
"""
import os
import unittest

from cli_testing import CliTestCase, read_meta, read_rows, run

TINY = ["--rays", "512", "--reps", "1", "--build-reps", "1", "--min-time", "0.001", "--warmup", "0"]
ANALYTIC = "proc:analytic_mix"


def procedural_scenes():
    """proc:<name> of every procedural scene `raybench scenes` lists."""
    listing = run("scenes").stdout.split("procedural scenes", 1)[-1]
    return {"proc:" + line.split()[0] for line in listing.splitlines() if line.startswith("  ")}


class TessellateCli(CliTestCase):

    def manifest(self, text):
        path = self.path("suite.toml")
        with open(path, "w") as f:
            f.write(text)
        return path

    def run_suite(self, suite, *args):
        return run("run", "--suite", suite, "--out", self.path("out.csv"), "--rays-dir", self.path("rays"),
                   *TINY, *args)

    def test_bad_resolutions_are_refused_before_any_scene_is_loaded(self):
        suite = self.manifest('[[scene]]\nname = "sphere"\npath = "proc:sphere"\n')
        for value, problem in (("2x8", "--tessellate: must be SxR: S segments (longitude, 3 to 4096) by R rings "
                                       "(latitude, 2 to 4096), e.g. 16x8; got '2x8'"),
                               ("8x4,8x4", "--tessellate: 8x4 is given twice"),
                               ("uv16x8", "got 'uv16x8'")):
            result = self.run_suite(suite, "--tessellate", value)
            self.assertBadInput(result, problem)
            self.assertNotIn("loading", result.stderr)
            self.assertFalse(os.path.exists(self.path("out.csv")))
        bad = self.manifest('[defaults]\ntessellate = ["16x8", "4097x8"]\n'
                            '[[scene]]\nname = "sphere"\npath = "proc:sphere"\n')
        self.assertBadInput(self.run_suite(bad), f"{bad}: 'defaults.tessellate': must be SxR", "got '4097x8'")

    def test_a_triangle_scene_is_traced_as_itself_only_and_the_metadata_names_the_resolutions(self):
        suite = self.manifest('[defaults]\ntessellate = ["8x4"]\nraysets = ["primary"]\n'
                              'backends = ["embree", "bvh2"]\n'
                              '[[scene]]\nname = "sphere"\npath = "proc:sphere"\n')
        result = self.run_suite(suite, "--tessellate", "8x4,32x16")
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = read_rows(self.path("out.csv"))
        self.assertEqual([(r["scene"], r["representation"]) for r in rows],
                         [("sphere", "triangles"), ("sphere", "triangles")])
        self.assertEqual(read_meta(self.path("out.csv"))["tessellate"], "8x4,32x16")
        # `none` turns the manifest's list off.
        result = self.run_suite(suite, "--tessellate", "none")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(read_meta(self.path("out.csv"))["tessellate"], "")

    def test_the_help_names_the_flag(self):
        self.assertIn("--tessellate", run("run", "--help").stdout)

    @unittest.skipUnless(ANALYTIC in procedural_scenes(), f"needs {ANALYTIC} (scenes with analytic primitives)")
    def test_each_stand_in_is_traced_with_the_scenes_rays_and_judged_by_its_referee(self):
        suite = self.manifest(f'[[scene]]\nname = "mix"\npath = "{ANALYTIC}"\n')
        result = self.run_suite(suite, "--tessellate", "8x4,64x32", "--rayset", "primary,shadow",
                                "--backend", "embree,bvh2", "--accuracy", self.path("acc.csv"))
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = read_rows(self.path("out.csv"))
        seen = {(r["scene"], r["representation"], r["backend"], r["rayset"]) for r in rows}
        # A backend that cannot model the scene is skipped for it, with a note, yet traces its
        # stand-ins (triangles); Embree models every type.
        skipped = read_meta(self.path("out.csv")).get("skipped", {}).get("mix", {})
        self.assertNotIn("embree", skipped)
        expected = {(scene, representation, backend, rayset)
                    for scene, representation in (("mix", "analytic"), ("mix@uv8x4", "uv8x4"),
                                                  ("mix@uv64x32", "uv64x32"))
                    for backend in ("embree", "bvh2") for rayset in ("primary", "shadow")
                    if representation != "analytic" or backend not in skipped}
        self.assertEqual(seen, expected)
        accuracy = {(r["scene"], r["rayset"], r["backend"]): r for r in read_rows(self.path("acc.csv"))}
        for (scene, rayset, backend), r in accuracy.items():
            analytic = accuracy[("mix", rayset, "embree")]
            # The same rays and the same referee: the same truth for every representation.
            self.assertEqual(r["truth_hits"], analytic["truth_hits"], (scene, rayset, backend))
            self.assertEqual(r["ambiguous"], analytic["ambiguous"], (scene, rayset, backend))
        error = {key: sum(float(r[k] or 0) for k in ("false_miss", "false_hit", "wrong_prim"))
                 for key, r in accuracy.items()}
        self.assertGreaterEqual(error[("mix@uv8x4", "primary", "embree")],
                                error[("mix@uv64x32", "primary", "embree")], "finer is no worse")


if __name__ == "__main__":
    unittest.main()
