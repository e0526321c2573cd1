#!/usr/bin/env python3
"""Reconstructs the sample (examples/fountain-P11-small) with the `tessera` module and
writes a PNG of the cameras and points seen from above.

    python3 examples/python/reconstruct_and_plot.py --output /tmp/fountain

(after `pip install .`, or with PYTHONPATH=build/lib/python3.11/dist-packages).

The world frame of a Tessera (or COLMAP) model is the first camera's: x right, y down,
z forward, so "from above" is the x-z plane.
"""

import argparse
import logging
import pathlib
import sys

import matplotlib  # type: ignore[import]

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # type: ignore[import]  # noqa: E402
import numpy as np  # noqa: E402

import tessera  # noqa: E402

SAMPLE = pathlib.Path(__file__).resolve().parents[1] / "fountain-P11-small" / "images"


def parse_arguments() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--images", type=pathlib.Path, default=SAMPLE)
    parser.add_argument("--output", type=pathlib.Path, required=True, help="workspace folder")
    parser.add_argument("--manifest", type=pathlib.Path, help="default: default.json")
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--png", type=pathlib.Path, help="default: OUTPUT/top_view.png")
    parser.add_argument("--verbose", action="store_true", help="the stages' log on stderr")
    return parser.parse_args()


def print_progress(stage: str, done: int, total: int) -> None:
    print(f"\r{stage}: {done}/{total}   ", end="", file=sys.stderr, flush=True)


def plot_from_above(model: tessera.Reconstruction, png: pathlib.Path) -> None:
    """Points (x, z) coloured as seen, camera centres and viewing directions in red."""
    points = model.points3D_arrays()
    figure, axes = plt.subplots(figsize=(8, 8))
    axes.scatter(points["xyz"][:, 0], points["xyz"][:, 2], s=1, c=points["colors"] / 255.0)
    centres = np.array([image.projection_center() for image in model.images.values()])
    # The optical axis in the world is the third row of R (cam_from_world).
    directions = np.array([image.cam_from_world.rotation.matrix()[2]
                           for image in model.images.values()])
    scale = 0.1 * np.ptp(centres, axis=0).max()
    axes.scatter(centres[:, 0], centres[:, 2], c="red", s=20, label="cameras")
    axes.quiver(centres[:, 0], centres[:, 2], directions[:, 0] * scale, directions[:, 2] * scale,
                color="red", angles="xy", scale_units="xy", scale=1, width=0.003)
    axes.set_xlabel("x")
    axes.set_ylabel("z")
    axes.set_aspect("equal")
    axes.set_title(f"{len(model.images)} cameras, {len(model.points3D)} points, from above")
    axes.legend(loc="upper right")
    figure.savefig(png, dpi=120)
    plt.close(figure)


def main() -> None:
    arguments = parse_arguments()
    if arguments.verbose:  # the log is Python's: nothing is printed unless asked for
        logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
    summary = tessera.run(images=arguments.images, output=arguments.output,
                          manifest=arguments.manifest, threads=arguments.threads,
                          progress=print_progress)
    print(file=sys.stderr)
    print(f"{summary['map']['num_registered']} of {summary['map']['num_images']} images "
          f"registered in {summary['map']['num_models']} model(s), "
          f"{summary['total_seconds']:.1f} s")
    model = tessera.Reconstruction(arguments.output / "sparse" / "0")
    png = arguments.png or arguments.output / "top_view.png"
    plot_from_above(model, png)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
