#!/usr/bin/env python3
"""Reading a large COLMAP model from Python against reading it in C++, and the memory
that the numpy views add over the C++ model.

    PYTHONPATH=build/lib/python3.11/dist-packages python3 benchmarks/python_read_model.py \
        build/bin/colmap_model_read_benchmark [--points 100000]

Writes a synthetic binary model (POINTS points, each seen by 3 of 200 images) in a
temporary folder, then prints:
  - the median time of ReadColmapModel in C++ (colmap_model_read_benchmark), of
    tessera.Reconstruction(path), and of that plus every array a script would take
    (points3D_arrays(), each image's keypoints and point3D_ids), and their ratios;
  - the resident memory of the model after reading it, and what the views of every
    image and every point add to it.
"""

import argparse
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import tessera

NUM_IMAGES = 200
TRACK_LENGTH = 3


def write_text_model(folder, num_points):
    """A consistent model: point p is seen by images p, p+1, p+2 (mod NUM_IMAGES)."""
    rng = np.random.default_rng(1)
    folder.mkdir(parents=True)
    (folder / "cameras.txt").write_text("1 PINHOLE 1000 800 500 500 500 400\n")
    keypoints = [[] for _ in range(NUM_IMAGES)]  # (x, y, point3D_id) per image
    tracks = []
    for point3D_id in range(1, num_points + 1):
        track = []
        for k in range(TRACK_LENGTH):
            image = (point3D_id + k) % NUM_IMAGES
            track.append(f"{image + 1} {len(keypoints[image])}")
            keypoints[image].append(point3D_id)
        tracks.append(" ".join(track))
    xyz = rng.normal(size=(num_points, 3))
    colors = rng.integers(0, 256, size=(num_points, 3))
    lines = [f"{i + 1} {x:.17g} {y:.17g} {z:.17g} {r} {g} {b} 0.5 {tracks[i]}"
             for i, ((x, y, z), (r, g, b)) in enumerate(zip(xyz, colors))]
    (folder / "points3D.txt").write_text("\n".join(lines) + "\n")
    lines = []
    for image in range(NUM_IMAGES):
        lines.append(f"{image + 1} 1 0 0 0 {image * 0.1} 0 0 1 image{image:04d}.jpg")
        lines.append(" ".join(f"{10.0 + j} {20.0 + j} {point3D_id}"
                              for j, point3D_id in enumerate(keypoints[image])))
    (folder / "images.txt").write_text("\n".join(lines) + "\n")


def median_seconds(function, repeats):
    seconds = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        seconds.append(time.perf_counter() - start)
    return statistics.median(seconds)


def resident_mb():
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * 4096 / 2**20


def take_every_array(model):
    arrays = [model.points3D_arrays()]
    for image in model.images.values():
        arrays.append((image.keypoints, image.point3D_ids))
    return arrays


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cpp_benchmark", nargs="?", help="build/bin/colmap_model_read_benchmark")
    parser.add_argument("--memory-of", type=pathlib.Path, help=argparse.SUPPRESS)
    parser.add_argument("--points", type=int, default=100000)
    parser.add_argument("--repeats", type=int, default=5)
    arguments = parser.parse_args()
    if arguments.memory_of:
        print_memory(arguments.memory_of)
        return
    with tempfile.TemporaryDirectory() as temporary:
        text, binary = pathlib.Path(temporary) / "text", pathlib.Path(temporary) / "binary"
        write_text_model(text, arguments.points)
        tessera.Reconstruction(text).write(binary, format="binary")

        cpp = subprocess.run([arguments.cpp_benchmark, binary, str(arguments.repeats)],
                             check=True, capture_output=True, text=True).stdout.split()
        cpp_seconds = float(cpp[1])
        read = median_seconds(lambda: tessera.Reconstruction(binary), arguments.repeats)
        read_and_arrays = median_seconds(
            lambda: take_every_array(tessera.Reconstruction(binary)), arguments.repeats)
        print(f"model: {cpp[3]} points, {cpp[5]} images, {TRACK_LENGTH} observations a point")
        print(f"C++ ReadColmapModel:            {cpp_seconds:.3f} s")
        print(f"Python Reconstruction(path):    {read:.3f} s  ratio {read / cpp_seconds:.2f}")
        print(f"  + every array of the model:   {read_and_arrays:.3f} s  "
              f"ratio {read_and_arrays / cpp_seconds:.2f}")

        # In a fresh interpreter: freed memory of the reads above would hide the model's.
        print(subprocess.run([sys.executable, __file__, "--memory-of", binary], check=True,
                             capture_output=True, text=True).stdout, end="")


def print_memory(binary):
    before = resident_mb()
    model = tessera.Reconstruction(binary)
    with_model = resident_mb()
    views = [point.xyz for point in model.points3D.values()]
    views += [image.keypoints for image in model.images.values()]
    with_views = resident_mb()
    print(f"memory: the model {with_model - before:.1f} MB; a view of every point's position "
          f"and every image's keypoints ({len(views)} views) adds {with_views - with_model:.1f} "
          f"MB, {(with_views - with_model) * 2**20 / len(views):.0f} bytes a view")

if __name__ == "__main__":
    main()
