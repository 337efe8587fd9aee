"""The dependency direction of the source tree, as README "Layout" states it: the kernels
include nothing of the harness, and each harness folder includes only the folders below it
in LAYERS (io first, the command line last), so a newcomer can read the tree bottom up.
"""
import os
import re
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
HARNESS = os.path.join(ROOT, "harness", "src")
LAYERS = ["io", "scene", "rays", "referee", "backends", "measure", "results", "accuracy", "suite", "cli"]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def includes(folder):
    """(file, included path) for every quoted include in the files of `folder`."""
    for dirpath, _, names in os.walk(folder):
        for name in names:
            if name.endswith((".h", ".cpp", ".in")):
                path = os.path.join(dirpath, name)
                with open(path, encoding="utf-8") as f:
                    for target in INCLUDE.findall(f.read()):
                        yield os.path.relpath(path, ROOT), target


class Layout(unittest.TestCase):
    def test_every_harness_source_sits_in_a_layer_folder(self):
        flat = [n for n in os.listdir(HARNESS) if os.path.isfile(os.path.join(HARNESS, n))]
        self.assertEqual(flat, [], "harness/src/ holds only folders, one per concern")
        self.assertEqual(sorted(d for d in os.listdir(HARNESS)), sorted(LAYERS))

    def test_each_folder_includes_only_folders_below_it(self):
        for layer, folder in enumerate(LAYERS):
            for path, target in includes(os.path.join(HARNESS, folder)):
                top = target.split("/")[0]
                if "/" not in target or top == "raybench" or top == folder:
                    continue  # its own folder, a kernel header or a generated header
                self.assertIn(top, LAYERS, f"{path} includes {target}")
                self.assertLess(LAYERS.index(top), layer, f"{path} ({folder}) includes {target}, a layer above it")

    def test_the_kernels_include_nothing_of_the_harness(self):
        for path, target in includes(os.path.join(ROOT, "kernels")):
            self.assertNotIn(target.split("/")[0], LAYERS, f"{path} includes {target}")


if __name__ == "__main__":
    unittest.main()
