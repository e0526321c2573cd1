#!/usr/bin/env python3
"""Prints what a model holds, as pycolmap's users read it: the summary, each image's pose
(quaternion in pycolmap's (x, y, z, w) order) and how well the points reproject.

    python3 examples/python/inspect_model.py sample-output/sparse/0
"""

import argparse
import pathlib

import numpy as np
import numpy.typing as npt

import tessera


def reprojection_errors(model: tessera.Reconstruction,
                        image: tessera.Image) -> "npt.NDArray[np.float64]":
    """Pixel distance between each observed keypoint of `image` and its 3D point projected."""
    ids = image.point3D_ids
    observed = np.flatnonzero(ids != np.iinfo(np.uint64).max)
    if len(observed) == 0:
        return np.zeros(0)
    xyz = np.array([model.points3D[int(ids[index])].xyz for index in observed])
    projected = model.project(image.image_id, xyz)
    return np.asarray(np.linalg.norm(projected - image.keypoints[observed], axis=1))


def main() -> None:
    parser = argparse.ArgumentParser(description="What a model holds")
    parser.add_argument("model", type=pathlib.Path, help="a model folder (sparse/0)")
    arguments = parser.parse_args()
    model = tessera.Reconstruction(arguments.model)
    print(model.summary())
    for image_id, image in sorted(model.images.items()):
        pose = image.cam_from_world
        errors = reprojection_errors(model, image)
        quat = ", ".join(f"{value:+.4f}" for value in pose.rotation.quat)
        print(f"{image!r}: quat (x, y, z, w) = ({quat}), "
              f"mean error {errors.mean() if len(errors) else 0.0:.3f} px")
    print(f"mean reprojection error: {model.compute_mean_reprojection_error():.3f} px")


if __name__ == "__main__":
    main()
