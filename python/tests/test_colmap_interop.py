"""Models that COLMAP 3.8 wrote (model_converter from the CLI's model) read back
exactly, write back byte for byte, and give the figures of `colmap model_analyzer`.
Without colmap the test skips, and fails under CI=true, as tests/end_to_end/common.sh's
skip_or_fail does."""

import filecmp
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

import tessera


@pytest.fixture(scope="module")
def colmap_models(sample, tmp_path_factory):
    if shutil.which("colmap") is None:
        if os.environ.get("CI") == "true":
            pytest.fail("CI: colmap (Debian package) is missing; this test must not skip in CI")
        pytest.skip("colmap is not installed")
    source = sample[2] / "sparse" / "0"
    root = tmp_path_factory.mktemp("colmap")
    for output_type in ("BIN", "TXT"):
        (root / output_type).mkdir()
        subprocess.run(["colmap", "model_converter", "--input_path", source, "--output_path",
                        root / output_type, "--output_type", output_type],
                       check=True, capture_output=True)
    return source, root / "BIN", root / "TXT"


def assert_same_model(expected, actual):
    assert list(expected.cameras) == list(actual.cameras)
    for camera_id, camera in expected.cameras.items():
        np.testing.assert_array_equal(camera.params, actual.cameras[camera_id].params)
    assert list(expected.images) == list(actual.images)
    for image_id, image in expected.images.items():
        other = actual.images[image_id]
        assert image.name == other.name
        np.testing.assert_array_equal(image.cam_from_world.rotation.quat,
                                      other.cam_from_world.rotation.quat)
        np.testing.assert_array_equal(image.cam_from_world.translation,
                                      other.cam_from_world.translation)
        np.testing.assert_array_equal(image.keypoints, other.keypoints)
        np.testing.assert_array_equal(image.point3D_ids, other.point3D_ids)
    mine, theirs = expected.points3D_arrays(), actual.points3D_arrays()
    for key in ("ids", "xyz", "colors", "errors"):
        np.testing.assert_array_equal(mine[key], theirs[key])
    for point3D_id, point in expected.points3D.items():
        np.testing.assert_array_equal(point.track, actual.points3D[point3D_id].track)


def test_colmap_models_read_back_exactly(colmap_models):
    source, binary, text = colmap_models
    ours = tessera.Reconstruction(source)
    assert_same_model(ours, tessera.Reconstruction(binary))
    # COLMAP's text keeps 17 significant digits: the same doubles.
    assert_same_model(ours, tessera.Reconstruction(text))


def test_colmap_files_write_back_byte_for_byte(colmap_models, tmp_path):
    _, binary, text = colmap_models
    tessera.Reconstruction(binary).write(tmp_path / "bin", format="binary")
    tessera.Reconstruction(text).write(tmp_path / "txt", format="text")
    for name in ("cameras", "images", "points3D"):
        assert filecmp.cmp(binary / f"{name}.bin", tmp_path / "bin" / f"{name}.bin",
                           shallow=False), name
        assert filecmp.cmp(text / f"{name}.txt", tmp_path / "txt" / f"{name}.txt",
                           shallow=False), name


def test_the_figures_of_colmap_model_analyzer(colmap_models):
    _, binary, _ = colmap_models
    log = subprocess.run(["colmap", "model_analyzer", "--path", binary], check=True,
                         capture_output=True, text=True)
    text = log.stdout + log.stderr

    def figure(label):
        return float(re.search(rf"{label}: ([0-9.]+)", text).group(1))

    model = tessera.Reconstruction(binary)
    statistics = model.statistics()
    assert figure("Cameras") == len(model.cameras)
    assert figure("Registered images") == model.num_reg_images()
    assert figure("Points") == len(model.points3D)
    assert figure("Observations") == statistics["num_observations"]
    assert figure("Mean track length") == pytest.approx(statistics["mean_track_length"], abs=1e-6)
    # COLMAP averages the points' stored errors.
    errors = model.points3D_arrays()["errors"]
    assert figure("Mean reprojection error") == pytest.approx(errors[errors >= 0].mean(), abs=1e-6)
