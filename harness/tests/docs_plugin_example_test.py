"""The complete C plugin of docs/plugins.md is a working plugin: the ```c block under
"A complete plugin in C" compiles as C99 against plugin/include/raybench/plugin.h without a
warning, exports raybench_plugin with the header's ABI version, and its table builds, traces
(closest and any hit, hits and misses as plugin.h defines them) and frees. The plugin is called
through ctypes, as the C ABI is, so this test needs no raybench binary.
"""
import ctypes as C
import math
import os
import re
import shutil
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
INCLUDE = os.path.join(ROOT, "plugin", "include")


def example_source():
    with open(os.path.join(ROOT, "docs", "plugins.md"), encoding="utf-8") as f:
        text = f.read()
    section = text.split("## A complete plugin in C", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"^```c\n(.*?)^```", section, re.S | re.M)
    assert len(blocks) == 1, "one ```c block under 'A complete plugin in C'"
    return blocks[0]


def abi_version():
    with open(os.path.join(INCLUDE, "raybench", "plugin.h"), encoding="utf-8") as f:
        return int(re.search(r"#define RAYBENCH_PLUGIN_ABI_VERSION (\d+)", f.read()).group(1))


# plugin.h's structs, field by field.
class Ray(C.Structure):
    _fields_ = [(n, C.c_float) for n in ("org_x", "org_y", "org_z", "tnear", "dir_x", "dir_y", "dir_z", "tfar")]


class Hit(C.Structure):
    _fields_ = [("t", C.c_float), ("prim", C.c_int32), ("u", C.c_float), ("v", C.c_float)]


class BuildInput(C.Structure):
    _fields_ = [("triangles", C.POINTER(C.c_float)), ("triangle_count", C.c_size_t), ("options", C.c_char_p),
                ("threads", C.c_int)]


class Table(C.Structure):
    _fields_ = [
        ("abi_version", C.c_uint32), ("name", C.c_char_p), ("description", C.c_char_p), ("accuracy_class", C.c_char_p),
        ("check_options", C.c_void_p),
        ("build", C.CFUNCTYPE(C.c_void_p, C.POINTER(BuildInput), C.c_char_p, C.c_size_t)),
        ("memory_bytes", C.CFUNCTYPE(C.c_size_t, C.c_void_p)),
        ("intersect", C.CFUNCTYPE(C.c_int, C.c_void_p, C.POINTER(Ray), C.c_size_t, C.POINTER(Hit))),
        ("occluded", C.CFUNCTYPE(C.c_int, C.c_void_p, C.POINTER(Ray), C.c_size_t, C.POINTER(C.c_uint8))),
        ("destroy", C.CFUNCTYPE(None, C.c_void_p)),
    ]


class DocsPluginExample(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp()
        source = os.path.join(cls.tmp, "brute.c")
        with open(source, "w", encoding="utf-8") as f:
            f.write(example_source())
        cls.library = os.path.join(cls.tmp, "brute.so")
        cc = shutil.which("cc") or shutil.which("gcc")
        assert cc, "a C compiler (cc) builds the example"
        # The build line of the doc, with every warning an error.
        subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-shared", "-fPIC",
                        "-fvisibility=hidden", "-I", INCLUDE, source, "-o", cls.library], check=True)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp)

    def table(self):
        lib = C.CDLL(self.library)
        lib.raybench_plugin.restype = C.POINTER(Table)
        return lib.raybench_plugin().contents

    def test_it_exports_only_the_entry_point_with_the_headers_abi_version(self):
        symbols = subprocess.run(["nm", "-D", "--defined-only", self.library], capture_output=True, text=True,
                                 check=True).stdout.split()
        self.assertIn("raybench_plugin", symbols)
        for hidden in ("build", "trace", "intersect", "occluded", "destroy"):
            self.assertNotIn(hidden, symbols)
        table = self.table()
        self.assertEqual(table.abi_version, abi_version())
        self.assertEqual(table.name, b"brute")
        self.assertEqual(table.accuracy_class, b"fast")

    def test_it_builds_traces_and_frees_as_plugin_h_says(self):
        table = self.table()
        # Triangle 0 at z = 0, triangle 1 under it at z = -1; rays straight down.
        triangles = (C.c_float * 18)(0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, -1, 1, 0, -1, 0, 1, -1)
        error = C.create_string_buffer(512)
        accel = table.build(C.byref(BuildInput(triangles, 2, b"", 1)), error, len(error))
        self.assertTrue(accel, error.value)
        self.assertEqual(table.memory_bytes(accel), 2 * 9 * 4)
        rays = (Ray * 4)(Ray(0.25, 0.25, 1, 0, 0, 0, -1, 10),   # hits both: the closer is triangle 0
                         Ray(2, 2, 1, 0, 0, 0, -1, 10),         # misses both
                         Ray(0.25, 0.25, 1, 1.5, 0, 0, -1, 10),  # tnear beyond triangle 0: triangle 1
                         Ray(0, 0, 0, 1, 1, 0, 0, 0))           # raybench's screened-out ray: empty interval
        hits = (Hit * 4)(*[Hit(-7, 99, -7, -7)] * 4)  # raybench does not clear the array
        self.assertEqual(table.intersect(accel, rays, 4, hits), 0)
        self.assertEqual((hits[0].t, hits[0].prim, hits[0].u, hits[0].v), (1.0, 0, 0.25, 0.25))
        self.assertEqual((hits[1].t, hits[1].prim), (math.inf, -1))
        self.assertEqual((hits[2].t, hits[2].prim), (2.0, 1))
        self.assertEqual((hits[3].t, hits[3].prim), (math.inf, -1))
        occluded = (C.c_uint8 * 4)(7, 7, 7, 7)
        self.assertEqual(table.occluded(accel, rays, 4, occluded), 0)
        self.assertEqual(list(occluded), [1, 0, 1, 0])
        table.destroy(accel)


if __name__ == "__main__":
    unittest.main()
