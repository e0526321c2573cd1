#!/usr/bin/env python3
"""A pycolmap user's first script, run on Tessera: each call as pycolmap spells it, and
where Tessera differs, its own call beside, as docs/python.md's table says. Prints each
call with "same" or "differs" and the counts (python/tests/test_pycolmap_style.py checks
them against the table).

    PYTHONPATH=build/lib/python3.11/dist-packages python3 examples/python/pycolmap_style.py \
        --workspace sample-output [--images IMAGES --manifest MANIFEST]
"""

import argparse
import copy
import pathlib
import pickle
import tempfile
from typing import Any, Callable, List, Optional, Tuple

import numpy as np

import tessera

SAME, DIFFERS = "same", "differs"


def checked_calls(workspace: pathlib.Path) -> List[Tuple[str, str, Callable[[], Any]]]:
    """(pycolmap call, SAME or DIFFERS, Tessera's call) for a workspace that has a model."""
    rec = tessera.Reconstruction(workspace / "sparse" / "0")
    image = next(iter(rec.images.values()))
    camera = rec.cameras[image.camera_id]
    point_id, point = next(iter(rec.points3D.items()))
    out = pathlib.Path(tempfile.mkdtemp())
    pose = image.cam_from_world
    other = rec.images[rec.reg_image_ids()[-1]].cam_from_world
    xyz = rec.points3D_arrays()["xyz"]
    sim3 = tessera.Sim3d(2.0, tessera.Rotation3d([0.0, 0.0, 0.6, 0.8]), np.array([1.0, 0, 0]))
    moved = copy.deepcopy(rec)
    pixels = camera.img_from_cam(pose * xyz[:10])
    calls: List[Tuple[str, str, Callable[[], Any]]] = [
        ("pycolmap.Reconstruction(path)", SAME, lambda: tessera.Reconstruction(
            workspace / "sparse" / "0")),
        ("pycolmap.Reconstruction()", SAME, lambda: tessera.Reconstruction()),
        ("rec.summary()", SAME, rec.summary),
        ("rec.num_reg_images()", SAME, rec.num_reg_images),
        ("rec.num_points3D()", SAME, rec.num_points3D),
        ("rec.num_cameras()", SAME, rec.num_cameras),
        ("rec.num_images()", SAME, rec.num_images),
        ("rec.compute_mean_reprojection_error()", SAME, rec.compute_mean_reprojection_error),
        ("rec.find_image_with_name(name)", SAME, lambda: rec.find_image_with_name(image.name)),
        ("rec.images.items()", SAME, lambda: list(rec.images.items())),
        ("rec.cameras[camera_id]", SAME, lambda: rec.cameras[image.camera_id]),
        ("rec.points3D[point3D_id]", SAME, lambda: rec.points3D[point_id]),
        ("rec.write(path)", SAME, lambda: rec.write(out / "binary")),
        ("rec.write_text(path)", DIFFERS, lambda: rec.write(out / "text", format="text")),
        ("pickle.dumps(rec)", SAME, lambda: pickle.loads(pickle.dumps(rec))),
        ("copy.deepcopy(rec)", SAME, lambda: copy.deepcopy(rec)),
        ("image.name", SAME, lambda: image.name),
        ("image.image_id", SAME, lambda: image.image_id),
        ("image.camera_id", SAME, lambda: image.camera_id),
        ("image.cam_from_world.rotation.quat", SAME, lambda: image.cam_from_world.rotation.quat),
        ("image.cam_from_world.rotation.matrix()", SAME,
         lambda: image.cam_from_world.rotation.matrix()),
        ("image.cam_from_world.translation", SAME, lambda: image.cam_from_world.translation),
        ("image.cam_from_world.matrix()", SAME, lambda: image.cam_from_world.matrix()),
        ("image.cam_from_world.inverse()", SAME, lambda: pose.inverse()),
        ("cam2_from_world * world_from_cam1", SAME, lambda: other * pose.inverse()),
        ("image.cam_from_world * point3D.xyz", SAME, lambda: pose * point.xyz),
        ("image.cam_from_world * points (N, 3)", SAME, lambda: pose * xyz),
        ("pycolmap.Rigid3d(rotation, translation)", SAME,
         lambda: tessera.Rigid3d(pose.rotation, pose.translation)),
        ("pycolmap.Rigid3d(matrix)", SAME, lambda: tessera.Rigid3d(pose.matrix())),
        ("pycolmap.Rotation3d(quat)", SAME, lambda: tessera.Rotation3d(pose.rotation.quat)),
        ("rotation.inverse()", SAME, lambda: pose.rotation.inverse()),
        ("rotation.angle_to(other)", SAME, lambda: pose.rotation.angle_to(other.rotation)),
        ("pycolmap.Sim3d(scale, rotation, translation)", SAME,
         lambda: tessera.Sim3d(2.0, pose.rotation, pose.translation)),
        ("sim3.scale, sim3.rotation, sim3.translation", SAME,
         lambda: (sim3.scale, sim3.rotation, sim3.translation)),
        ("sim3.matrix()", SAME, sim3.matrix),
        ("sim3.inverse()", SAME, sim3.inverse),
        ("sim3 * sim3", SAME, lambda: sim3 * sim3.inverse()),
        ("sim3 * points", SAME, lambda: sim3 * xyz),
        ("sim3.transform_camera_world(cam_from_world)", SAME,
         lambda: sim3.transform_camera_world(pose)),
        ("pickle.dumps(image.cam_from_world)", SAME, lambda: pickle.loads(pickle.dumps(pose))),
        ("rec.transform(sim3)", SAME, lambda: moved.transform(sim3)),
        ("rec.normalize()", SAME, moved.normalize),
        ("rec.reg_image_ids()", SAME, rec.reg_image_ids),
        ("rec.compute_mean_track_length()", SAME, rec.compute_mean_track_length),
        ("image.projection_center()", SAME, image.projection_center),
        ("image.viewing_direction()", SAME, image.viewing_direction),
        ("image.num_points3D", DIFFERS, image.num_points3D),
        ("camera.model", DIFFERS, lambda: camera.model),
        ("camera.width, camera.height", SAME, lambda: (camera.width, camera.height)),
        ("camera.params", SAME, lambda: camera.params),
        ("camera.calibration_matrix()", SAME, camera.calibration_matrix),
        ("camera.img_from_cam(points)", DIFFERS,
         lambda: camera.img_from_cam(np.array([[0.1, 0.2, 1.0]]))),
        ("camera.cam_from_img(pixels)", SAME, lambda: camera.cam_from_img(pixels)),
        ("camera.focal_length", DIFFERS, lambda: camera.focal_length),
        ("camera.focal_length_x, camera.focal_length_y", SAME,
         lambda: (camera.focal_length_x, camera.focal_length_y)),
        ("camera.mean_focal_length()", SAME, camera.mean_focal_length),
        ("point3D.xyz", SAME, lambda: point.xyz),
        ("point3D.color", SAME, lambda: point.color),
        ("point3D.error", SAME, lambda: point.error),
        ("point3D.track", DIFFERS, lambda: point.track),
        ("image.points2D", SAME, lambda: image.points2D),
        ("point2D.has_point3D()", SAME, lambda: [p.has_point3D() for p in image.points2D]),
        ("rec.exists_point3D(point3D_id)", SAME, lambda: rec.exists_point3D(point_id)),
        ("rec.exists_image(image_id)", SAME, lambda: rec.exists_image(image.image_id)),
        ("pycolmap.bundle_adjustment(rec)", SAME, lambda: tessera.bundle_adjustment(moved)),
        ("pycolmap.align_reconstructions_via_proj_centers(src, tgt, max_proj_center_error)",
         SAME, lambda: tessera.align_reconstructions_via_proj_centers(rec, moved, 0.1)),
    ]
    return calls + edit_calls(copy.deepcopy(rec)) + estimator_calls(rec)


def edit_calls(rec: tessera.Reconstruction) -> List[Tuple[str, str, Callable[[], Any]]]:
    """Adding a camera, an image and a point, and deleting observations and points, in order
    on one model."""
    camera = tessera.Camera("PINHOLE", 640, 480, [500.0, 500.0, 320.0, 240.0], camera_id=99)
    image = tessera.Image(name="added.jpg", points2D=np.array([[10.0, 20.0], [30.0, 40.0]]),
                          cam_from_world=tessera.Rigid3d(), camera_id=99, image_id=999)
    first = rec.images[rec.reg_image_ids()[0]]
    free = int(np.flatnonzero(first.point3D_ids == np.iinfo(np.uint64).max)[0])
    track = tessera.Track()
    ids: List[int] = []
    some_point = next(iter(rec.points3D))
    return [
        ("pycolmap.Image(name=..., points2D=..., cam_from_world=..., camera_id=..., "
         "image_id=...)", SAME, lambda: image),
        ("rec.add_camera(camera)", SAME, lambda: rec.add_camera(camera)),
        ("rec.add_image(image)", SAME, lambda: rec.add_image(image)),
        ("rec.register_image(image_id)", SAME, lambda: rec.register_image(999)),
        ("pycolmap.Track(); track.add_elements(elements)", SAME,
         lambda: track.add_elements([(999, 0), (first.image_id, free)])),
        ("rec.add_point3D(xyz, track, color)", SAME,
         lambda: ids.append(rec.add_point3D(np.zeros(3), track, np.array([255, 0, 0])))),
        ("rec.add_observation(point3D_id, track_element)", SAME,
         lambda: rec.add_observation(ids[0], tessera.TrackElement(999, 1))),
        ("rec.delete_observation(image_id, point2D_idx)", SAME,
         lambda: rec.delete_observation(999, 1)),
        ("rec.delete_point3D(point3D_id)", SAME, lambda: rec.delete_point3D(some_point)),
        ("rec.deregister_image(image_id)", SAME, lambda: rec.deregister_image(999)),
    ]


def estimator_calls(rec: tessera.Reconstruction) -> List[Tuple[str, str, Callable[[], Any]]]:
    """The robust estimators on a registered image's 2D-3D correspondences and on the
    matches of two images that see the same points."""
    none = np.iinfo(np.uint64).max
    image_ids = rec.reg_image_ids()
    image1 = rec.images[image_ids[0]]
    seen = image1.point3D_ids != none
    points2D = image1.keypoints[seen]
    points3D = np.array([rec.points3D[int(i)].xyz for i in image1.point3D_ids[seen]])
    # The image that sees most of image1's points; keypoints of one point: putative matches.
    ids1 = set(int(i) for i in image1.point3D_ids[seen])
    image2 = max((rec.images[i] for i in image_ids[1:]),
                 key=lambda other: len(ids1 & set(int(i) for i in other.point3D_ids)))
    camera1, camera2 = rec.cameras[image1.camera_id], rec.cameras[image2.camera_id]
    index2 = {int(p): k for k, p in enumerate(image2.point3D_ids) if p != none}
    pairs = [(k, index2[int(p)]) for k, p in enumerate(image1.point3D_ids) if int(p) in index2]
    points1 = image1.keypoints[[k for k, _ in pairs]]
    points2 = image2.keypoints[[k for _, k in pairs]]
    return [
        ("pycolmap.estimate_absolute_pose(points2D, points3D, camera)", DIFFERS,
         lambda: tessera.estimate_absolute_pose(points2D, points3D, camera1)),
        ("pycolmap.estimate_essential_matrix(points1, points2, camera1, camera2)", DIFFERS,
         lambda: tessera.estimate_essential_matrix(points1, points2, camera1, camera2)),
        ("pycolmap.estimate_fundamental_matrix(points1, points2)", DIFFERS,
         lambda: tessera.estimate_fundamental_matrix(points1, points2)),
        ("pycolmap.estimate_homography_matrix(points1, points2)", DIFFERS,
         lambda: tessera.estimate_homography_matrix(points1, points2)),
        ("pycolmap.estimate_two_view_geometry(camera1, points1, camera2, points2)", DIFFERS,
         lambda: tessera.estimate_two_view_geometry(camera1, points1, camera2, points2)),
        ("pycolmap.Camera(model, width, height, params)", SAME,
         lambda: tessera.Camera("SIMPLE_PINHOLE", 640, 480, [500.0, 320.0, 240.0])),
    ]


def stage_calls(images: pathlib.Path,
                manifest: Optional[pathlib.Path]) -> List[Tuple[str, str, Callable[[], Any]]]:
    """pycolmap's pipeline functions on WORKSPACE/database.db. `manifest` (Tessera's keyword,
    for CI's fast recipe) replaces the default recipe; without it each call is pycolmap's
    as written."""
    database_path = pathlib.Path(tempfile.mkdtemp()) / "database.db"
    models = {}
    return [
        ("pycolmap.extract_features(database_path, image_path)", SAME,
         lambda: tessera.extract_features(database_path, images, manifest=manifest)),
        ("pycolmap.match_exhaustive(database_path)", SAME,
         lambda: tessera.match_exhaustive(database_path, manifest=manifest)),
        ("pycolmap.incremental_mapping(database_path, image_path, output_path)", SAME,
         lambda: models.update(tessera.incremental_mapping(database_path, images,
                                                           database_path.parent / "models",
                                                           manifest=manifest))),
        ("pycolmap.triangulate_points(rec, database_path, image_path, output_path)", SAME,
         lambda: tessera.triangulate_points(models[0], database_path, images,
                                            database_path.parent / "triangulated",
                                            manifest=manifest)),
        ("pycolmap.Database.open(path)", SAME, lambda: tessera.Database.open(database_path)),
        ("db.read_all_images()", SAME,
         lambda: tessera.Database.open(database_path).read_all_images()),
        ("db.read_keypoints(image_id)", SAME,
         lambda: tessera.Database.open(database_path).read_keypoints(1)),
        ("db.read_descriptors(image_id).data", SAME,
         lambda: tessera.Database.open(database_path).read_descriptors(1).data),
        ("db.read_matches(image_id1, image_id2)", SAME,
         lambda: tessera.Database.open(database_path).read_matches(1, 2)),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--workspace", type=pathlib.Path, required=True,
                        help="a workspace with a model, e.g. `tessera run`'s output")
    parser.add_argument("--images", type=pathlib.Path,
                        help="also run the stages on these images, in a new workspace")
    parser.add_argument("--manifest", type=pathlib.Path, help="the stages' recipe")
    arguments = parser.parse_args()
    counts = {SAME: 0, DIFFERS: 0}
    calls = checked_calls(arguments.workspace)
    if arguments.images:
        calls += stage_calls(arguments.images, arguments.manifest)
    for call, kind, function in calls:
        function()
        counts[kind] += 1
        print(f"{kind:8} {call}")
    print(f"{counts[SAME]} calls run unchanged, {counts[DIFFERS]} need a documented difference")


if __name__ == "__main__":
    main()
