"""Scenes with analytic primitives agree with Embree (issue 31): where Embree and our BVHs model a
scene identically (spheres as spheres, boxes and oriented boxes as boxes), every backend agrees with
Embree on hit or miss for at least 99.99 % of the rays of every everyday ray set. (Which primitive
each backend hits, by global id, is analytic_cli_test's.)

Scenes: proc:analytic_mix (every primitive type, nested and rotated) and
proc:terrain_spheres_analytic_small (a terrain with analytic balls on it). sphere_field is left
out on purpose: its ground sphere of radius 1e5 makes every float sphere test self-intersect on
secondary rays in its own way (docs/accuracy.md), which is what the accuracy suite shows.
ctest sets RAYBENCH (harness/tests/CMakeLists.txt).
"""
import unittest

import cli_testing
from cli_testing import CliTestCase, read_rows

BACKENDS = ["embree", "bvh2", "bvh8", "bvh4", "bvh8:watertight", "reference"]
RAYSETS = ["primary", "diffuse", "shadow", "uniform"]


class AgreementWithEmbree(CliTestCase):
    def test_every_backend_agrees_with_embree_on_hit_or_miss_for_99_99_percent(self):
        out = self.path("run.csv")
        result = cli_testing.run("run", "--scene", "proc:analytic_mix,proc:terrain_spheres_analytic_small",
                                 "--rayset", ",".join(RAYSETS), "--rays", "20000", "--reps", "1",
                                 "--min-time", "0.01", "--backend", ",".join(BACKENDS), "--out", out,
                                 "--rays-dir", self.path("rays"), "--tessellate", "none")
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = read_rows(out)
        seen = {(r["scene"], r["rayset"], r["backend"]) for r in rows}
        for scene in ("analytic_mix", "terrain_spheres_analytic_small"):
            for rayset in RAYSETS:
                for backend in BACKENDS:
                    self.assertIn((scene, rayset, backend), seen)
        for r in rows:
            with self.subTest(scene=r["scene"], rayset=r["rayset"], backend=r["backend"]):
                self.assertEqual(r["representation"], "analytic")
                self.assertGreaterEqual(float(r["agree_hit"]), 0.9999)
                self.assertGreater(float(r["hit_rate"]), 0.0)


if __name__ == "__main__":
    unittest.main()
