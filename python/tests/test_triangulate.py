"""tessera.triangulate (issue 58): the sample's own model as known poses, triangulated again
from the workspace's matches in a child process; the poses come back bit for bit, and bad
input is an InputError naming the file."""

import shutil

import numpy as np
import pytest

import tessera


def test_triangulate_keeps_the_poses_and_finds_points(sample, tmp_path):
    images, manifest, cli = sample
    known = tessera.Reconstruction(cli / "sparse" / "0")
    known.write(tmp_path / "known", format="text")
    workspace = tmp_path / "workspace"
    workspace.mkdir()
    shutil.copy(cli / "database.db", workspace / "database.db")

    summary = tessera.triangulate(output=workspace, model=tmp_path / "known", model_index=1,
                                  manifest=manifest)
    assert summary["images_in_common"] == len(known.images)
    assert summary["only_in_source"] == []
    assert summary["num_points3D"] > 0.5 * len(known.points3D)
    assert summary["mean_reprojection_error"] < 1.5
    assert not summary["refined_intrinsics"]

    model = tessera.Reconstruction(workspace / "sparse" / "1")
    assert len(model.points3D) == summary["num_points3D"]
    by_name = {image.name: image for image in known.images.values()}
    for image in model.images.values():
        source = by_name[image.name]
        assert image._cam_from_world_quat == source._cam_from_world_quat
        np.testing.assert_array_equal(image.cam_from_world.translation,
                                      source.cam_from_world.translation)
    np.testing.assert_array_equal(model.cameras[1].params, known.cameras[1].params)

    # The manifest's bundle adjuster refines the intrinsics, the poses held.
    refined = tessera.triangulate(output=workspace, model=tmp_path / "known", model_index=2,
                                  refine_intrinsics=True, manifest=manifest)
    assert refined["refined_intrinsics"] and refined["mean_reprojection_error"] < 1.5
    model = tessera.Reconstruction(workspace / "sparse" / "2")
    for image in model.images.values():
        assert image._cam_from_world_quat == by_name[image.name]._cam_from_world_quat


def test_triangulate_refuses_bad_input(sample, tmp_path):
    images, manifest, cli = sample
    workspace = tmp_path / "workspace"
    workspace.mkdir()
    shutil.copy(cli / "database.db", workspace / "database.db")
    with pytest.raises(tessera.InputError, match="give one of them"):
        tessera.triangulate(output=workspace)
    with pytest.raises(tessera.InputError, match="no COLMAP model"):
        tessera.triangulate(output=workspace, model=tmp_path)
    poses = tmp_path / "transforms.json"
    poses.write_text('{"w": 512, "h": 341, "fl_x": 400, "frames": [{"file_path": "x.png", '
                     '"transform_matrix": [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], '
                     '[0, 0, 0, 1]]}]}')
    with pytest.raises(tessera.InputError, match=r"frames\[0\] \(x.png\).*not a rotation"):
        tessera.triangulate(output=workspace, poses=poses)
    with pytest.raises(TypeError, match="model_index"):
        tessera.triangulate(output=workspace, model=tmp_path, model_index="1")
