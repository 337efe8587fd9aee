"""Render a scene's primary-ray view as a depth image and print the scene's
bounds and camera (see scripts/preview_camera)."""
import argparse
import math
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RAYBENCH = os.environ.get("RAYBENCH", os.path.join(ROOT, "build", "raybench"))
# The run's threshold (harness/src/suite/results_table.h, kMinCameraCoverage).
MIN_CAMERA_COVERAGE = 0.25


def parse(argv):
    p = argparse.ArgumentParser(prog="scripts/preview_camera", description=__doc__)
    p.add_argument("scene", help="a suite scene's name, a mesh path or proc:<name>")
    p.add_argument("out", nargs="?", help="PNG to write (default: <scene>_camera.png)")
    p.add_argument("width", nargs="?", type=int, default=320, help="image width in pixels (default 320)")
    p.add_argument("--suite", help="suite manifest the scene name is looked up in (default: meshes/default.toml)")
    return p.parse_args(argv)


def main(argv):
    args = parse(argv[1:])
    scene = args.scene
    out = args.out or f"{os.path.basename(scene).split('.')[0].replace(':', '_')}_camera.png"
    suite = ["--suite", args.suite] if args.suite else []
    aspect = float(np.float32(4.0 / 3.0))  # Camera::aspect
    height = int(round(args.width / aspect))
    count = args.width * height
    grid_w = math.ceil(math.sqrt(count * aspect))  # the grid RayGenerator::primary lays out
    if subprocess.run([RAYBENCH, "scenes", "--bounds", "--scene", scene, *suite]).returncode != 0:
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        rays, hits = os.path.join(tmp, "rays.npy"), os.path.join(tmp, "hits.npy")
        for cmd in ([RAYBENCH, "rays", "--scene", scene, *suite, "--kind", "primary", "-n", str(count), "-o", rays],
                    [RAYBENCH, "trace", "--scene", scene, *suite, "--rays", rays, "-b", "embree", "-o", hits]):
            if subprocess.run(cmd, stdout=subprocess.DEVNULL).returncode != 0:
                return 2
        t = np.load(hits)[:, 0]
    rows = math.ceil(count / grid_w)
    image = np.full(grid_w * rows, np.inf)
    image[:count] = t
    image = image.reshape(rows, grid_w)
    finite = np.isfinite(image)
    shade = np.zeros_like(image)
    if finite.any():
        near, far = np.percentile(image[finite], [1, 99])
        shade[finite] = 1.0 - 0.85 * np.clip((image[finite] - near) / max(far - near, 1e-12), 0, 1)
    plt.imsave(out, shade, cmap="gray", vmin=0, vmax=1)
    hit = np.isfinite(t).mean()
    print(f"{out}: {hit:.1%} of primary rays hit")
    if hit < MIN_CAMERA_COVERAGE:
        print(f"warning: the camera sees little of the scene (a run warns below {MIN_CAMERA_COVERAGE:.0%}): "
              "set camera = { position = [...], look_at = [...] } for it in the manifest, look_at inside the bounds above")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
