"""Scenes with analytic primitives on the command line (issue 31): a suite manifest naming
spheres, boxes and obbs .npy files beside a mesh (analytic_scene/scene.toml), listed,
given rays, traced by its name, and every malformed primitive file refused by every
command with one line naming the file and the row.

Run through ctest (harness/tests/CMakeLists.txt sets RAYBENCH).
"""
import os
import shutil
import unittest

import numpy as np

from cli_testing import CliTestCase, run

HERE = os.path.dirname(os.path.abspath(__file__))
FIXTURES = os.path.join(HERE, "analytic_scene")
SUITE = os.path.join(FIXTURES, "scene.toml")

# What the fixture files hold (np.save of these arrays); prim ids follow the
# ground's 2 triangles: spheres 2-4, boxes 5-6, the oriented box 7.
H = np.sqrt(0.5)
SPHERES = np.array([[-4, 1, 0, 1], [0, 1, 0, 1], [0, 1, 0, 0.25]], dtype=np.float32)
BOXES = np.array([[3, 0, -1, 5, 2, 1], [-1, 0, 3, 1, 1, 5]], dtype=np.float64)
OBBS = np.array([[0, 1, -4, H, 0, -H, 0, 1, 0, H, 0, H, 1, 1, 1]], dtype=np.float64)  # a cube turned 45 degrees about y

DOWN, UP, EAST, NORTH = (0, -1, 0), (0, 1, 0), (1, 0, 0), (0, 0, 1)
# (origin, direction, tfar, expected prim, expected t): each ray aimed at one
# primitive, with the surface semantics of docs/scenes.md.
AIMED = [
    ((-4, 10, 0), DOWN, np.inf, 2, 8.0),              # the first sphere's top
    ((-10, 1, 0), EAST, np.inf, 2, 5.0),              # its side
    ((0, 10, 0), DOWN, np.inf, 3, 8.0),               # the second sphere, around the nested third
    ((0, 1, 0), EAST, np.inf, 4, 0.25),               # from inside both: the nested sphere's far side first
    ((-4, 1, 0), NORTH, 0.5, -1, np.inf),             # from inside, its far side beyond tfar: a miss
    ((4, 10, 0), DOWN, np.inf, 5, 8.0),               # the first box's top
    ((4, 1, 0), UP, np.inf, 5, 1.0),                  # from inside the box: its far side
    ((0, 10, 4), DOWN, np.inf, 6, 9.0),               # the second box
    ((-10, 1, -4), EAST, np.inf, 7, 10.0 - np.sqrt(2.0)),  # the turned cube's edge at x = -sqrt(2)
    ((8, 10, -8), DOWN, np.inf, 0, 10.0),             # the ground's first triangle
    ((0, 10, 0), UP, np.inf, -1, np.inf),             # nothing above
]


def aimed_rays():
    rays = np.zeros((len(AIMED), 8), dtype=np.float32)
    for i, (o, d, tfar, _, _) in enumerate(AIMED):
        rays[i] = [*o, 0.0, *d, tfar]
    return rays


class AnalyticScene(CliTestCase):
    def copy_fixtures(self):
        """The fixture folder in this test's folder, to spoil one file of it."""
        folder = self.path("scene")
        shutil.copytree(FIXTURES, folder)
        return folder

    def test_the_fixture_files_hold_the_documented_arrays(self):
        for name, array in (("spheres.npy", SPHERES), ("boxes.npy", BOXES), ("obbs.npy", OBBS)):
            stored = np.load(os.path.join(FIXTURES, name))
            self.assertEqual(stored.dtype, array.dtype, name)  # float32 and float64 are both read
            self.assertTrue(np.array_equal(stored, array), name)

    def test_scenes_lists_the_files_and_says_what_each_scene_holds(self):
        listing = run("scenes", "--suite", SUITE)
        self.assertEqual(listing.returncode, 0, listing.stderr)
        self.assertIn("spheres " + os.path.join(FIXTURES, "spheres.npy"), listing.stdout)
        bounds = run("scenes", "--suite", SUITE, "--bounds", "--scene", "mixed,analytic_only")
        self.assertEqual(bounds.returncode, 0, bounds.stderr)
        self.assertIn("mixed: 2 triangles, 3 spheres, 2 boxes, 1 oriented box", bounds.stdout)
        self.assertIn("analytic_only: 0 triangles, 3 spheres, 2 boxes, 1 oriented box", bounds.stdout)

    def test_primary_rays_for_the_mixed_scene_by_its_name(self):
        out = self.path("primary.npy")
        result = run("rays", "--suite", SUITE, "--scene", "mixed", "--kind", "primary", "-n", "500", "-o", out)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("(2 triangles, 3 spheres, 2 boxes, 1 oriented box)", result.stdout)
        self.assertEqual(np.load(out).shape, (500, 8))

    # Needs a backend that models analytic primitives: bvh2 and bvh8 (helper "ours"), embree
    # (helper "embree") and reference (helper "referee"). Before their work is merged, bvh2
    # traces the ground only and this test fails.
    def test_trace_by_scene_name_hits_each_primitive_by_its_global_id(self):
        rays = self.path("aimed.npy")
        np.save(rays, aimed_rays())
        for backend in ("bvh2", "bvh8", "embree", "reference"):
            with self.subTest(backend=backend):
                out = self.path(f"hits_{backend}.npy")
                result = run("trace", "--suite", SUITE, "--scene", "mixed", "--rays", rays, "-b", backend, "-o", out)
                self.assertEqual(result.returncode, 0, result.stderr)
                hits = np.load(out)
                for i, (o, d, _, prim, t) in enumerate(AIMED):
                    self.assertEqual(int(hits[i, 1]), prim, f"ray {i} from {o} along {d}: t prim u v = {hits[i]}")
                    if prim < 0:
                        self.assertEqual(hits[i, 0], np.inf)
                        continue
                    self.assertAlmostEqual(hits[i, 0], t, delta=1e-5 * t, msg=f"ray {i}")
                    if prim >= 2:  # analytic hits report u = v = 0
                        self.assertEqual((hits[i, 2], hits[i, 3]), (0.0, 0.0), f"ray {i}")

    def test_a_malformed_primitive_file_is_one_line_naming_the_file_and_the_row_for_every_command(self):
        folder = self.copy_fixtures()
        suite = os.path.join(folder, "scene.toml")
        rays = self.path("aimed.npy")
        np.save(rays, aimed_rays())
        spoiled = [
            ("spheres.npy", SPHERES * np.array([1, 1, 1, -1], dtype=np.float32), "row 0: radius is -1: it must be >= 0"),
            ("boxes.npy", np.ascontiguousarray(BOXES[:, [3, 1, 2, 0, 4, 5]]), "row 0: min_x 5 > max_x 3"),
            ("obbs.npy", np.where(np.arange(15) == 7, 0.5, OBBS), "row 0: axis 1 (0, 0.5, 0) has length 0.5"),
            ("spheres.npy", np.vstack([SPHERES, [[0, np.nan, 0, 1]]]).astype(np.float32), "row 3: column 1 (cy) is nan"),
            ("obbs.npy", OBBS[:, :12], "shape is (1, 12), expected (N, 15)"),
        ]
        for name, array, problem in spoiled:
            file = os.path.join(folder, name)
            original = np.load(file)
            np.save(file, array)
            for command in (["scenes", "--suite", suite, "--bounds", "--scene", "mixed"],
                            ["rays", "--suite", suite, "--scene", "mixed", "--kind", "primary", "-n", "10",
                             "-o", self.path("r.npy")],
                            ["trace", "--suite", suite, "--scene", "mixed", "--rays", rays, "-b", "bvh2",
                             "-o", self.path("h.npy")],
                            ["run", "--suite", suite, "--scene", "mixed", "--out", self.path("run.csv"),
                             "--rays-dir", self.path("rays")]):
                with self.subTest(file=name, problem=problem, command=command[0]):
                    self.assertBadInput(run(*command), f"{file}: {problem}")
                    self.assertFalse(os.path.exists(self.path("run.csv")))
            np.save(file, original)

    def test_a_missing_primitive_file_is_named(self):
        folder = self.copy_fixtures()
        os.remove(os.path.join(folder, "boxes.npy"))
        result = run("run", "--suite", os.path.join(folder, "scene.toml"), "--out", self.path("run.csv"),
                     "--rays-dir", self.path("rays"))
        self.assertBadInput(result, "scene 'mixed': " + os.path.join(folder, "boxes.npy") + " not found")


if __name__ == "__main__":
    unittest.main()
