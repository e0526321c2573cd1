#!/bin/bash
# Open3D, an independent PLY reader, opens the ply exporter's file: COLMAP's fountain-P11
# model exported with `tessera export --format ply` and camera centres must read back
# with every point, in id order, with the model's colours, and the camera centres after
# them in their colour. Skipped (exit 77, with a message) when no python3 with open3d
# (Debian: python3-open3d) or the shared anchors are found; missing anchors are a failure
# under CI=true (common.sh's skip_or_fail).
# usage: ply_open3d_test.sh TESSERA SHARED_DIR
set -uo pipefail
tessera=$1
shared=${TESSERA_SHARED_DIR:-$2}
source "$(dirname "$0")/../end_to_end/common.sh"
anchor="$shared/anchors/colmap-3.8/fountain-P11"
[ -d "$anchor/sparse-txt" ] || skip_or_fail "COLMAP's fountain-P11 model not found at $anchor"
python=""
for candidate in python3 /usr/bin/python3; do
  if "$candidate" -c "import open3d" > /dev/null 2>&1; then
    python=$candidate
    break
  fi
done
[ -n "$python" ] ||
  skip_or_fail "no python3 with open3d (apt-get install python3-open3d); the PLY check with" \
               "Open3D did not run"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$tessera" export --model "$anchor/sparse/0" --format ply --output "$work" \
  --options '{"camera_centers": true, "camera_center_color": [255, 0, 0]}' 2> "$work/export.log" ||
  { cat "$work/export.log"; echo "FAIL: tessera export --format ply"; exit 1; }

"$python" - "$work/sparse/0/points3D.ply" "$anchor/sparse-txt" << 'PYTHON'
import sys

import numpy as np
import open3d

ply_path, model_dir = sys.argv[1], sys.argv[2]
points = {}
with open(f"{model_dir}/points3D.txt") as file:
    for line in file:
        if line.startswith("#") or not line.strip():
            continue
        fields = line.split()
        points[int(fields[0])] = ([float(v) for v in fields[1:4]], [int(v) for v in fields[4:7]])
num_images = sum(1 for line in open(f"{model_dir}/images.txt") if not line.startswith("#")) // 2

cloud = open3d.io.read_point_cloud(ply_path)
xyz = np.asarray(cloud.points)
rgb = np.rint(np.asarray(cloud.colors) * 255).astype(int)
expected_xyz = np.array([points[i][0] for i in sorted(points)])
expected_rgb = np.array([points[i][1] for i in sorted(points)])
n = len(points)
print(f"open3d read {len(xyz)} vertices: {n} points + {len(xyz) - n} camera centres "
      f"(model: {n} points, {num_images} images)")
assert len(xyz) == n + num_images, "vertex count"
assert cloud.has_colors(), "no colours"
error = np.abs(xyz[:n] - expected_xyz).max()
assert error <= 1e-6 * max(1.0, np.abs(expected_xyz).max()), f"coordinates off by {error}"
assert (rgb[:n] == expected_rgb).all(), "point colours differ from the model's"
assert (rgb[n:] == [255, 0, 0]).all(), "camera centres are not red"
print("PASS")
PYTHON
