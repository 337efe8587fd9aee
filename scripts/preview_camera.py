"""Render a scene's primary-ray view as a depth image (see scripts/preview_camera)."""
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


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__ + "\nusage: scripts/preview_camera SCENE [OUT.png] [WIDTH]")
        return 0 if len(argv) >= 2 else 2
    scene = argv[1]
    out = argv[2] if len(argv) > 2 else f"{os.path.basename(scene).split('.')[0].replace(':', '_')}_camera.png"
    width = int(argv[3]) if len(argv) > 3 else 320
    aspect = float(np.float32(4.0 / 3.0))  # Camera::aspect
    height = int(round(width / aspect))
    count = width * height
    grid_w = math.ceil(math.sqrt(count * aspect))  # the grid RayGenerator::primary lays out
    with tempfile.TemporaryDirectory() as tmp:
        rays, hits = os.path.join(tmp, "rays.npy"), os.path.join(tmp, "hits.npy")
        for cmd in ([RAYBENCH, "rays", "--scene", scene, "--kind", "primary", "-n", str(count), "-o", rays],
                    [RAYBENCH, "trace", "--scene", scene, "--rays", rays, "-b", "embree", "-o", hits]):
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
    print(f"{out}: {finite.mean():.1%} of primary rays hit")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
