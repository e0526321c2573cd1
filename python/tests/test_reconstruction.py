"""tessera.Reconstruction against the host's files: what it reads, the arrays over it,
projection, a byte-for-byte round trip, and the errors of bad models."""

import filecmp
import gc
import shutil

import numpy as np
import pytest

import tessera


@pytest.fixture
def model_dir(sample):
    return sample[2] / "sparse" / "0"


def test_reads_the_cli_model_as_mappings(model_dir):
    model = tessera.Reconstruction(model_dir)
    statistics = model.statistics()
    assert len(model.cameras) == statistics["num_cameras"] == 1
    assert len(model.images) == statistics["num_images"] == model.num_reg_images() >= 8
    assert len(model.points3D) == statistics["num_points3D"] > 500
    assert repr(model) == (f"Reconstruction(cameras=1, images={len(model.images)}, "
                           f"points3D={len(model.points3D)})")
    camera = next(iter(model.cameras.values()))
    assert camera.model == "SIMPLE_RADIAL"
    assert (camera.width, camera.height) == (512, 342)
    assert camera.params.shape == (4,)
    names = sorted(image.name for image in model.images.values())
    assert names[0] == "0000.jpg"
    # Every track element names a keypoint whose 3D point is the point itself.
    for point3D_id, point in model.points3D.items():
        for image_id, point2D_idx in point.track:
            assert model.images[image_id].point3D_ids[point2D_idx] == point3D_id


def test_arrays_have_their_shapes_and_views_share_memory(model_dir):
    model = tessera.Reconstruction(model_dir)
    arrays = model.points3D_arrays()
    n = len(model.points3D)
    assert arrays["ids"].shape == (n,) and arrays["ids"].dtype == np.uint64
    assert arrays["xyz"].shape == (n, 3) and arrays["xyz"].dtype == np.float64
    assert arrays["colors"].shape == (n, 3) and arrays["colors"].dtype == np.uint8
    assert arrays["errors"].shape == (n,)
    first = int(arrays["ids"][0])
    np.testing.assert_array_equal(arrays["xyz"][0], model.points3D[first].xyz)
    image = next(iter(model.images.values()))
    keypoints = image.keypoints
    assert keypoints.shape == (len(image.point3D_ids), 2) and keypoints.dtype == np.float64
    # Views over the C++ storage: no data of their own, the same memory on every access.
    assert not keypoints.flags.owndata
    assert np.shares_memory(keypoints, image.keypoints)
    assert np.shares_memory(model.points3D[first].xyz, model.points3D[first].xyz)
    assert model.points3D[first].track.shape[1] == 2
    # A view keeps the model alive: its data outlives every name of the model.
    expected = arrays["xyz"][0].copy()
    view = model.points3D[first].xyz
    del model, image, keypoints
    gc.collect()
    np.testing.assert_array_equal(view, expected)
    model = tessera.Reconstruction(model_dir)
    image = next(iter(model.images.values()))
    # The mappings are read-only: a deletion would free what the views point into.
    with pytest.raises(TypeError):
        del model.points3D[first]
    with pytest.raises(TypeError):
        model.images[image.image_id] = image


def test_poses_and_projection_agree_with_the_host(model_dir):
    model = tessera.Reconstruction(model_dir)
    for image in model.images.values():
        pose = image.cam_from_world
        rotation, translation = pose.rotation.matrix(), pose.translation
        np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(image.projection_center(), -rotation.T @ translation,
                                   atol=1e-9)
    # Projected from Python: the mean over points of each point's mean error over its
    # track is the host's mean_reprojection_error (COLMAP's figure, what `colmap
    # model_analyzer` and pycolmap's compute_mean_reprojection_error report); the mean over
    # every observation is mean_observation_reprojection_error.
    errors = []
    point_errors = []
    for point in model.points3D.values():
        track_errors = []
        for image_id, point2D_idx in point.track:
            pixel = model.project(int(image_id), point.xyz.reshape(1, 3))[0]
            track_errors.append(
                np.linalg.norm(pixel - model.images[image_id].keypoints[point2D_idx]))
        errors.extend(track_errors)
        point_errors.append(np.mean(track_errors))
    statistics = model.statistics()
    assert np.mean(point_errors) == pytest.approx(statistics["mean_reprojection_error"],
                                                  rel=1e-9)
    assert np.mean(errors) == pytest.approx(statistics["mean_observation_reprojection_error"],
                                            rel=1e-9)
    # The two differ on a real model: the test tells them apart.
    assert abs(np.mean(point_errors) - np.mean(errors)) > 1e-6
    assert np.mean(errors) < 4.0


def test_binary_round_trip_is_byte_for_byte(model_dir, tmp_path):
    model = tessera.Reconstruction(model_dir)
    model.write(tmp_path / "binary", format="binary")
    for name in ("cameras.bin", "images.bin", "points3D.bin"):
        assert filecmp.cmp(model_dir / name, tmp_path / "binary" / name, shallow=False), name
    # Through text and back: the same binary files again.
    model.write(tmp_path / "text", format="text")
    tessera.Reconstruction(tmp_path / "text").write(tmp_path / "again")
    for name in ("cameras.bin", "images.bin", "points3D.bin"):
        assert filecmp.cmp(model_dir / name, tmp_path / "again" / name, shallow=False), name


def test_bad_path_corrupt_model_and_format_raise_input_error(model_dir, tmp_path):
    with pytest.raises(tessera.InputError, match="no_such_model"):
        tessera.Reconstruction(tmp_path / "no_such_model")
    corrupt = tmp_path / "corrupt"
    shutil.copytree(model_dir, corrupt)
    data = (corrupt / "points3D.bin").read_bytes()
    (corrupt / "points3D.bin").write_bytes(data[: len(data) // 2])
    with pytest.raises(tessera.InputError, match="points3D.bin"):
        tessera.Reconstruction(corrupt)
    with pytest.raises(tessera.InputError, match="'png'"):
        tessera.Reconstruction(model_dir).write(tmp_path / "x", format="png")
    assert issubclass(tessera.InputError, tessera.Error)
    assert tessera.InputError.exit_code == 2


def test_views_are_read_only_and_setters_check_what_they_are_given(model_dir, tmp_path):
    model = tessera.Reconstruction(model_dir)
    camera = model.cameras[next(iter(model.cameras.keys()))]
    image = model.images[next(iter(model.images.keys()))]
    point3D_id = next(iter(model.points3D.keys()))
    point = model.points3D[point3D_id]
    views = {"Camera.params": camera.params, "Image.keypoints": image.keypoints,
             "Image.point3D_ids": image.point3D_ids, "Point3D.xyz": point.xyz,
             "Point3D.color": point.color, "Point3D.track": point.track}
    for name, view in views.items():
        assert not view.flags.writeable, name
        with pytest.raises(ValueError, match="read-only"):
            view[0] = 0
        # Nor can it be made writeable again: its memory is the model's.
        with pytest.raises(ValueError):
            view.setflags(write=True)
    # The explicit setters change the model, and refuse what a model cannot hold.
    point.xyz = [1.0, 2.0, 3.0]
    np.testing.assert_array_equal(model.points3D[point3D_id].xyz, [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"Point3D.xyz: value 1 is nan, not a finite number"):
        point.xyz = [1.0, float("nan"), 3.0]
    with pytest.raises(ValueError, match=r"Point3D.xyz: expected 3 numbers"):
        point.xyz = [1.0, 2.0]
    params = camera.params.copy()
    params[0] *= 1.5
    camera.params = params
    np.testing.assert_array_equal(model.cameras[camera.camera_id].params, params)
    with pytest.raises(ValueError, match=rf"Camera {camera.camera_id}.params: value 0 is inf"):
        camera.params = [float("inf")] + list(params[1:])
    with pytest.raises(ValueError, match=r"expected 4 numbers"):
        camera.params = params[:3]
    # What was set is written and read back.
    model.write(tmp_path / "moved")
    again = tessera.Reconstruction(tmp_path / "moved")
    np.testing.assert_array_equal(again.points3D[point3D_id].xyz, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(again.cameras[camera.camera_id].params, params)


def test_write_refuses_a_value_that_is_not_finite(model_dir, tmp_path):
    import ctypes

    model = tessera.Reconstruction(model_dir)
    point3D_id = next(iter(model.points3D.keys()))
    point = model.points3D[point3D_id]
    # Past the read-only view, as a C extension could: a NaN in the model's memory.
    ctypes.c_double.from_address(point.xyz.ctypes.data + 8).value = float("nan")
    with pytest.raises(ValueError,
                       match=rf"write: point3D {point3D_id}: xyz\[1\] is nan, not a finite number"):
        model.write(tmp_path / "nan")
    assert not (tmp_path / "nan").exists()
    image_id = next(iter(model.images.keys()))
    image = model.images[image_id]
    ctypes.c_double.from_address(point.xyz.ctypes.data + 8).value = 0.0
    ctypes.c_double.from_address(image.keypoints.ctypes.data).value = float("inf")
    with pytest.raises(ValueError, match=rf"write: image {image_id} \('{image.name}'\): keypoint 0\[0\] is inf"):
        model.write(tmp_path / "inf")
