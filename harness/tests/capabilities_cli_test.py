"""Backends that cannot model a scene, on the command line (issue 31): a run skips a triangle-only
backend (a plugin) for a scene with analytic primitives, prints why and records it in the metadata,
and measures it on the run's other scenes; `raybench trace` refuses such a pair in one line; Embree
traces the same scene with hits on every primitive type by their global ids.

The scene is proc:analytic_mix (36 triangles, then 8 spheres, 6 boxes and 6 oriented boxes).
ctest sets RAYBENCH and RAYBENCH_PLUGIN_GOOD_PLUGIN (harness/tests/CMakeLists.txt).
"""
import os
import unittest

import numpy as np

import cli_testing
from cli_testing import CliTestCase, read_meta, read_rows

TRIANGLES = 36  # analytic_mix's; its analytic primitives' ids follow


def good_plugin():
    return "plugin:" + os.environ["RAYBENCH_PLUGIN_GOOD_PLUGIN"]


def down_rays(path):
    """A grid of rays straight down onto analytic_mix's 16 x 16 floor, from above everything."""
    grid = np.linspace(-7.5, 7.5, 61)
    # Offset apart so that no ray runs along a floor triangle's edge or diagonal.
    rays = [[x + 0.1, 20.0, z + 0.03, 0.0, 0.0, -1.0, 0.0, np.inf] for x in grid for z in grid]
    np.save(path, np.array(rays, dtype=np.float32))
    return path


class SkippedBackends(CliTestCase):
    def test_a_run_skips_a_triangle_only_plugin_on_the_analytic_scene_only_and_records_why(self):
        out = self.path("run.csv")
        plugin = good_plugin()
        result = cli_testing.run("run", "--scene", "proc:axis_boxes,proc:analytic_mix", "--rayset", "primary,shadow",
                                 "--rays", "2000", "--reps", "1", "--min-time", "0.01",
                                 "--backend", f"embree,{plugin}", "--out", out, "--rays-dir", self.path("rays"))
        self.assertEqual(result.returncode, 0, result.stderr)
        reason = (f"backend '{plugin}' models triangles only; "
                  "scene 'analytic_mix' has spheres, boxes and oriented boxes")
        self.assertIn(f"{plugin}: skipped, {reason}", result.stderr)
        pairs = {(r["scene"], r["backend"]) for r in read_rows(out)}
        self.assertEqual(pairs, {("axis_boxes", "embree"), ("axis_boxes", plugin), ("analytic_mix", "embree")})
        meta = read_meta(out)
        self.assertEqual(meta["status"], "complete")
        self.assertEqual(meta["skipped"], {"analytic_mix": {plugin: reason}})

    def test_a_run_of_triangle_scenes_skips_nothing(self):
        out = self.path("run.csv")
        result = cli_testing.run("run", "--scene", "proc:axis_boxes", "--rayset", "primary", "--rays", "500",
                                 "--reps", "1", "--min-time", "0.01", "--backend", f"embree,{good_plugin()}",
                                 "--out", out, "--rays-dir", self.path("rays"))
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertNotIn("skipped", result.stderr)
        self.assertNotIn("skipped", read_meta(out))


class Trace(CliTestCase):
    def test_trace_refuses_a_backend_that_cannot_model_the_scene_in_one_line(self):
        result = cli_testing.run("trace", "--scene", "proc:analytic_mix", "--rays", down_rays(self.path("r.npy")),
                                 "--backend", good_plugin(), "--out", self.path("h.npy"))
        self.assertBadInput(result, "--backend", "models triangles only", "scene 'analytic_mix' has spheres")
        self.assertFalse(os.path.exists(self.path("h.npy")))

    def test_embree_hits_every_type_by_its_global_id_with_u_v_zero_for_analytic_hits(self):
        result = cli_testing.run("trace", "--scene", "proc:analytic_mix", "--rays", down_rays(self.path("r.npy")),
                                 "--backend", "embree", "--out", self.path("h.npy"))
        self.assertEqual(result.returncode, 0, result.stderr)
        hits = np.load(self.path("h.npy"))
        hit = hits[:, 1] >= 0
        self.assertTrue(hit.all())  # the floor under everything
        analytic = hits[:, 1] >= TRIANGLES
        self.assertGreater(analytic.sum(), 100)
        self.assertGreater((~analytic).sum(), 100)
        self.assertTrue((hits[analytic, 2:] == 0).all())
        self.assertLess(hits[:, 1].max(), TRIANGLES + 8 + 6 + 6)
        # Seen from above, analytic primitives stand on or above the floor: nearer than it.
        self.assertLess(hits[analytic, 0].max(), 20.0 + 0.2 + 1e-3)


if __name__ == "__main__":
    unittest.main()
