"""tessera.register on the downscaled sample: 8 images mapped, then the other 3 placed
into the model with its poses held byte for byte, each reported; the bad inputs raise
InputError naming them."""

import shutil
import struct

import pytest

import tessera
from conftest import MANIFEST

NEW = ("0008.jpg", "0009.jpg", "0010.jpg")  # 0000 to 0007 a sequence that maps whole


def pose_records(model_dir):
    """images.bin's records by name: qvec, tvec and camera id, as bytes."""
    data = (model_dir / "images.bin").read_bytes()
    (count,), offset = struct.unpack_from("<Q", data, 0), 8
    records = {}
    for _ in range(count):
        end = data.index(b"\0", offset + 64)
        name = data[offset + 64:end].decode()
        records[name] = data[offset + 4:offset + 64]
        (num_points,) = struct.unpack_from("<Q", data, end + 1)
        offset = end + 1 + 8 + 24 * num_points
    return records


def test_register_places_three_new_images_holding_the_model(sample, tmp_path):
    all_images, _, _ = sample
    images = tmp_path / "images"
    images.mkdir()
    for path in sorted(all_images.glob("*.jpg")):
        if path.name not in NEW:
            shutil.copy(path, images / path.name)
    output = tmp_path / "ws"
    tessera.run(images=images, output=output, manifest=MANIFEST, threads=2)
    model = output / "sparse" / "0"
    before = pose_records(model)
    assert len(before) == 8

    for name in NEW:
        shutil.copy(all_images / name, images / name)
    calls = []
    summary = tessera.register(output=output, manifest=MANIFEST, threads=2,
                               progress=lambda stage, done, total: calls.append(stage))
    assert summary["num_new_images"] == 3
    assert sorted(image["name"] for image in summary["images"]) == sorted(NEW)
    assert summary["num_registered"] == 3, summary["images"]
    assert summary["num_images_after"] == 11
    after = pose_records(model)
    assert len(after) == 11
    for name, record in before.items():
        assert after[name] == record, f"{name}: the held pose changed"
    assert {"extract", "match", "register"} <= set(calls)
    assert len(tessera.Reconstruction(model).images) == 11

    # Nothing new now: InputError, the model untouched.
    with pytest.raises(tessera.InputError, match="no new images"):
        tessera.register(output=output, manifest=MANIFEST, threads=2)
    with pytest.raises(tessera.InputError, match="no model 4"):
        tessera.register(output=output, manifest=MANIFEST, model_index=4)
    with pytest.raises(tessera.InputError, match="model_index: Value -1"):
        tessera.register(output=output, manifest=MANIFEST, model_index=-1)
    with pytest.raises(tessera.InputError, match="no workspace database"):
        tessera.register(output=tmp_path / "none", manifest=MANIFEST)
    with pytest.raises(TypeError, match="refine_existing must be a bool"):
        tessera.register(output=output, refine_existing=1)
    assert pose_records(model) == after
