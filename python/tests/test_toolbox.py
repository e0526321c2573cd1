"""tessera.adjust and tessera.align, the twins of `tessera adjust` and `tessera align`, on the
sample's model (conftest.py)."""

import json

import numpy as np
import pytest

import tessera


def test_adjust_holds_the_intrinsics_and_reports_the_errors(sample, tmp_path):
    _, manifest, cli_output = sample
    model = cli_output / "sparse" / "0"
    summary = tessera.adjust(model=model, output=tmp_path / "adjusted", manifest=manifest,
                             hold=["intrinsics"])
    assert summary["held"] == ["intrinsics"] and summary["format"] == "binary"
    # The model was adjusted by the map already: the error stays where it was.
    assert summary["mean_reprojection_error_after"] <= 1.05 * summary[
        "mean_reprojection_error_before"]
    assert summary["num_points3D"] + summary["num_points3D_filtered"] == summary[
        "num_points3D_before"]
    before, after = tessera.Reconstruction(model), tessera.Reconstruction(tmp_path / "adjusted")
    assert len(after.points3D) == summary["num_points3D"]
    for camera_id, camera in before.cameras.items():
        assert np.array_equal(after.cameras[camera_id].params, camera.params)
    with pytest.raises(tessera.InputError, match="hold: unknown block 'focal'"):
        tessera.adjust(model=model, output=tmp_path / "x", hold=["focal"])
    assert not (tmp_path / "x").exists()


def test_align_onto_itself_and_upright(sample, tmp_path):
    _, _, cli_output = sample
    model = cli_output / "sparse" / "0"
    same = tessera.align(model=model, output=tmp_path / "same", reference=model)
    assert same["method"] == "reference"
    assert abs(same["scale"] - 1) < 1e-9
    assert np.allclose(same["rotation"], np.eye(3), atol=1e-9)
    assert same["num_inliers"] == len(tessera.Reconstruction(model).images)
    written = json.loads((tmp_path / "same" / "alignment.json").read_text())
    assert written["scale"] == same["scale"] and len(written["inliers"]) == same["num_inliers"]

    upright = tessera.align(model=model, output=tmp_path / "upright", upright=True)
    assert upright["method"] == "upright"
    assert upright["mean_up_angle_after_deg"] < 30
    assert (tmp_path / "upright" / "images.bin").is_file()
    with pytest.raises(tessera.InputError, match="exactly one of"):
        tessera.align(model=model, output=tmp_path / "none")
    with pytest.raises(TypeError, match="upright must be a bool"):
        tessera.align(model=model, output=tmp_path / "none", upright="yes")
