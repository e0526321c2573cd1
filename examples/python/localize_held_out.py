#!/usr/bin/env python3
"""Localises held-out photos into a model of the others, as a pycolmap user (hloc's
localisation) would: map the rest, give each 3D point a descriptor of an image that sees
it, match each held-out photo's features to the points with a ratio test (numpy),
estimate_absolute_pose from those 2D-3D matches, then compare the camera centres with the
Strecha ground truth (gt/*.camera) after a similarity fitted to the mapped images' centres.

    PYTHONPATH=build/lib/python3.11/dist-packages python3 examples/python/localize_held_out.py \
        ../shared/datasets/fountain-P11 /tmp/localise [--max-size 1024]

Prints one line per held-out photo, "NAME: inliers N/M, position error X cm", and exits 1
when one could not be localised.

Written against pycolmap 4's API: the only line that differs from a pycolmap script is
`import tessera as pycolmap`. The features of every image are Tessera's (extract_features
runs Tessera's default recipe), so the held-out photos' descriptors are of the same kind as
the model's.
"""

import argparse
import pathlib
import shutil
import sys
from typing import Dict, List, Tuple

import numpy as np
import numpy.typing as npt

import tessera as pycolmap  # the one line that differs from a pycolmap script

F64 = npt.NDArray[np.float64]
F32 = npt.NDArray[np.float32]


def parse_arguments() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("dataset", type=pathlib.Path,
                        help="a folder with images/ and gt/NAME.camera (Strecha's format)")
    parser.add_argument("output", type=pathlib.Path, help="the work folder")
    parser.add_argument("--held-out", default="0002.jpg,0005.jpg,0008.jpg",
                        help="the photos left out of the model, comma-separated")
    parser.add_argument("--max-size", type=int, default=0,
                        help="downscale the copies to at most this many pixels a side "
                             "(0: full size)")
    parser.add_argument("--ratio", type=float, default=0.8, help="Lowe's ratio test")
    return parser.parse_args()


def copy_images(names: List[str], source: pathlib.Path, target: pathlib.Path,
                max_size: int) -> None:
    """The images `names` of `source` into `target`, downscaled to max_size when given."""
    target.mkdir(parents=True, exist_ok=True)
    for name in names:
        if max_size <= 0:
            shutil.copyfile(source / name, target / name)
            continue
        import cv2  # type: ignore[import]  # python3-opencv; only to downscale

        image = cv2.imread(str(source / name), cv2.IMREAD_COLOR)
        if image is None:
            sys.exit(f"{source / name}: cannot read the image")
        scale = max_size / max(image.shape[:2])
        if scale < 1.0:
            size = (round(image.shape[1] * scale), round(image.shape[0] * scale))
            image = cv2.resize(image, size, interpolation=cv2.INTER_AREA)
        cv2.imwrite(str(target / name), image, [cv2.IMWRITE_JPEG_QUALITY, 95])


def ground_truth_centre(camera_file: pathlib.Path) -> F64:
    """C of a Strecha .camera file: K (9 numbers), distortion (3), R (9), C (3), size (2)."""
    numbers = [float(word) for word in camera_file.read_text().split()]
    if len(numbers) != 26:
        sys.exit(f"{camera_file}: {len(numbers)} numbers, not the 26 of a .camera file")
    return np.array(numbers[21:24])


def umeyama(source: F64, target: F64) -> Tuple[float, F64, F64]:
    """(s, R, t) minimising |target - (s R source + t)|^2 over rows (Umeyama 1991)."""
    source_mean, target_mean = source.mean(axis=0), target.mean(axis=0)
    a, b = source - source_mean, target - target_mean
    u, singular, vt = np.linalg.svd(b.T @ a / len(source))
    sign = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[2, 2] = -1.0
    rotation = u @ sign @ vt
    scale = float(np.trace(np.diag(singular) @ sign) / (a ** 2).sum(axis=1).mean())
    return scale, rotation, target_mean - scale * rotation @ source_mean


def normalised(descriptors: npt.NDArray[np.uint8]) -> F32:
    rows: F32 = descriptors.astype(np.float32)
    rows /= np.maximum(np.linalg.norm(rows, axis=1, keepdims=True), 1e-12)
    return rows


def ratio_matches(queries: F32, train: F32, ratio: float) -> npt.NDArray[np.int64]:
    """(K, 2) pairs (query row, train row) whose nearest train row is nearer than `ratio`
    times the second nearest, in L2 distance of unit rows."""
    pairs = []
    for start in range(0, len(queries), 1024):  # a block of dot products at a time
        similarity = queries[start:start + 1024] @ train.T
        # Column 0: the most similar row; column 1: the second (argpartition at kth=1).
        best_two = np.argpartition(-similarity, 1, axis=1)[:, :2]
        rows = np.arange(len(best_two))
        nearest = best_two[:, 0]
        first, second = similarity[rows, nearest], similarity[rows, best_two[:, 1]]
        distance1 = np.sqrt(np.maximum(2.0 - 2.0 * first, 0.0))
        distance2 = np.sqrt(np.maximum(2.0 - 2.0 * second, 0.0))
        keep = distance1 < ratio * distance2
        pairs.append(np.stack([rows[keep] + start, nearest[keep]], axis=1))
    return np.concatenate(pairs) if pairs else np.zeros((0, 2), np.int64)


def point_descriptors(rec: pycolmap.Reconstruction,
                      db: pycolmap.Database) -> Tuple[F64, F32]:
    """The model's points (N, 3) and a descriptor of each: that of the first keypoint that
    observes it, from the database's features of that keypoint's image."""
    db_ids = {image.name: image.image_id for image in db.read_all_images()}
    xyz: Dict[int, F64] = {}
    descriptors: Dict[int, npt.NDArray[np.uint8]] = {}
    for image_id in rec.reg_image_ids():
        image = rec.images[image_id]
        image_descriptors = db.read_descriptors(db_ids[image.name]).data
        for point2D_idx, point2D in enumerate(image.points2D):
            if point2D.has_point3D() and point2D.point3D_id not in xyz:
                xyz[point2D.point3D_id] = rec.points3D[point2D.point3D_id].xyz
                descriptors[point2D.point3D_id] = image_descriptors[point2D_idx]
    ids = sorted(xyz)
    return (np.array([xyz[i] for i in ids]),
            normalised(np.array([descriptors[i] for i in ids])))


def main() -> int:
    arguments = parse_arguments()
    images = arguments.dataset / "images"
    held_out = arguments.held_out.split(",")
    if not images.is_dir():
        sys.exit(f"{images}: no such folder (DATASET must hold images/ and gt/)")
    names = sorted(path.name for path in images.iterdir() if path.is_file())
    if not set(held_out) <= set(names):
        sys.exit(f"{images}: has no {sorted(set(held_out) - set(names))}")
    mapped = [name for name in names if name not in held_out]
    out = arguments.output
    copy_images(mapped, images, out / "images" / "mapped", arguments.max_size)
    copy_images(held_out, images, out / "images" / "held_out", arguments.max_size)

    # The model of the others.
    database_path = out / "map" / "database.db"
    pycolmap.extract_features(database_path, out / "images" / "mapped")
    pycolmap.match_exhaustive(database_path)
    reconstructions = pycolmap.incremental_mapping(database_path, out / "images" / "mapped",
                                                   out / "map" / "models")
    rec = reconstructions[0]
    print(f"model: {rec.num_reg_images()} of {len(mapped)} images, "
          f"{rec.num_points3D()} points")
    points3D, train = point_descriptors(rec, pycolmap.Database.open(database_path))

    # The similarity from the model's frame to the ground truth's, by the camera centres.
    registered = [rec.images[image_id] for image_id in rec.reg_image_ids()]
    if len(registered) < 3:
        sys.exit(f"only {len(registered)} images registered: no similarity to fit")
    scale, rotation, translation = umeyama(
        np.array([image.projection_center() for image in registered]),
        np.array([ground_truth_centre(arguments.dataset / "gt" / f"{image.name}.camera")
                  for image in registered]))

    # The held-out photos' features, as the model's.
    query_database_path = out / "held_out" / "database.db"
    pycolmap.extract_features(query_database_path, out / "images" / "held_out")
    query_db = pycolmap.Database.open(query_database_path)
    camera = rec.cameras[registered[0].camera_id]  # the mapped photos' camera, refined
    failed = 0
    for image in sorted(query_db.read_all_images(), key=lambda image: image.name):
        keypoints = query_db.read_keypoints(image.image_id)[:, :2].astype(np.float64)
        descriptors = query_db.read_descriptors(image.image_id).data
        matches = ratio_matches(normalised(descriptors), train, arguments.ratio)
        answer = None
        if len(matches) >= 4:
            answer = pycolmap.estimate_absolute_pose(keypoints[matches[:, 0]],
                                                    points3D[matches[:, 1]], camera)
        if answer is None:
            print(f"{image.name}: not localised ({len(matches)} matches)")
            failed += 1
            continue
        centre = answer["cam_from_world"].inverse().translation
        error = np.linalg.norm(scale * rotation @ centre + translation - ground_truth_centre(
            arguments.dataset / "gt" / f"{image.name}.camera"))
        print(f"{image.name}: inliers {answer['num_inliers']}/{len(matches)}, "
              f"position error {100.0 * error:.2f} cm")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
