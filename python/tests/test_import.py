"""tessera.import_features and tessera.import_matches from numpy arrays: SIFT features of
OpenCV's Python API (standing in for a learned model) on the sample at 512 px, imported
with raw matches verified by Tessera, and with matches OpenCV's RANSAC kept imported as
verified; each workspace mapped: 11/11. Bad arrays raise InputError naming the image (or
pair) and the row."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import tessera

cv2 = pytest.importorskip("cv2", reason="python3-opencv is not installed")

MANIFEST = {
    "pipeline": {
        "detector": {"plugin": "sift"},
        "pair_selector": {"plugin": "exhaustive"},
        "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": True}},
        "bundle_adjuster": {"plugin": "ceres"},
        "exporters": [{"plugin": "colmap_binary"}],
    },
    "camera": {"model": "SIMPLE_RADIAL", "single_camera": True},
    "verification": {"max_error_px": 4.0, "min_num_inliers": 15},
}


@pytest.fixture(scope="module")
def opencv_features(tmp_path_factory):
    """(images, K file, {name: (N x 4 keypoints, N x 128 RootSIFT float32)}, names)."""
    root = tmp_path_factory.mktemp("import")
    source = pathlib.Path(os.environ["TESSERA_SOURCE_DIR"])
    images = root / "images"
    subprocess.run(
        [os.environ["TESSERA_TEST_DOWNSCALE"], source / "examples/fountain-P11-small/images",
         images, "512", "90"], check=True, capture_output=True)
    camera_K = root / "K.txt"  # the sample's K.txt is for 1024 px: halved
    camera_K.write_text("459.9135 0 253.5315\n0 460.916 167.963\n0 0 1\n")
    sift = cv2.SIFT_create(nfeatures=3000, contrastThreshold=0.02)
    features = {}
    names = sorted(p.name for p in images.iterdir())
    for name in names:
        gray = cv2.imread(str(images / name), cv2.IMREAD_GRAYSCALE)
        keypoints, descriptors = sift.detectAndCompute(gray, None)
        frames = np.array([(k.pt[0] + 0.5, k.pt[1] + 0.5, k.size / 2, np.deg2rad(k.angle))
                           for k in keypoints])
        root_sift = np.sqrt(descriptors / np.maximum(descriptors.sum(1, keepdims=True), 1e-9))
        features[name] = (frames, root_sift.astype(np.float32))
    return images, camera_K, features, names


def opencv_matches(features, names, ransac):
    """{(a, b): M x 2} for every pair: mutual nearest neighbours, RANSAC's inliers if asked."""
    matcher = cv2.BFMatcher(cv2.NORM_L2, crossCheck=True)
    matches = {}
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            found = matcher.match(features[a][1], features[b][1])
            m = np.array([[x.queryIdx, x.trainIdx] for x in found if x.distance < 0.7],
                         dtype=np.int64).reshape(-1, 2)
            if ransac and len(m) >= 8:
                _, mask = cv2.findFundamentalMat(features[a][0][m[:, 0], :2],
                                                 features[b][0][m[:, 1], :2],
                                                 cv2.FM_RANSAC, 2.0, 0.999)
                m = m[mask.ravel() > 0] if mask is not None else m[:0]
            matches[(a, b)] = m
    return matches


def registered(output):
    return json.loads((output / "mapping_summary.json").read_text())["models"][0]["num_images"]


@pytest.mark.parametrize("verified", [False, True])
def test_imported_features_and_matches_map_every_image(opencv_features, tmp_path, verified):
    images, camera_K, features, names = opencv_features
    output = tmp_path / "ws"
    summary = tessera.import_features(output, features, images=images, manifest=MANIFEST,
                                      camera_K=camera_K, threads=2)
    assert summary["num_imported"] == 11
    assert summary["descriptors"] == "unit_float"
    assert summary["dimension"] == 128
    imported = tessera.import_matches(output, opencv_matches(features, names, ransac=verified),
                                      verified=verified, manifest=MANIFEST, threads=2)
    assert imported["num_pairs"] == 55
    assert imported["num_verified"] >= 20
    if verified:
        assert imported["num_inliers"] == imported["num_matches"]
    else:
        assert imported["num_inliers"] < imported["num_matches"]
    tessera.map(output, manifest=MANIFEST, camera_K=camera_K, threads=2)
    assert registered(output) == 11


def test_whole_number_descriptors_are_stored_as_they_are(opencv_features, tmp_path):
    images, _, features, names = opencv_features
    output = tmp_path / "ws"
    uint8 = {name: (frames[:, :2], np.clip(np.round(d * 512), 0, 255).astype(np.uint8))
             for name, (frames, d) in features.items()}
    summary = tessera.import_features(output, uint8, images=images, manifest=MANIFEST)
    assert summary["descriptors"] == "uint8"
    database = tessera.Database(output / "database.db")
    image = next(i for i in database.images.values() if i.name == names[0])
    assert np.array_equal(database.descriptors(image.image_id), uint8[names[0]][1])


def test_bad_arrays_name_the_image_and_row(opencv_features, tmp_path):
    images, _, features, names = opencv_features
    bad = dict(features)
    frames = features[names[1]][0].copy()
    frames[3, 1] = np.nan
    bad[names[1]] = (frames, features[names[1]][1])
    with pytest.raises(tessera.InputError, match=r"features\['0001.jpg'\] row 3: keypoint "
                                                 r"coordinates"):
        tessera.import_features(tmp_path / "nan", bad, images=images, manifest=MANIFEST)
    bad = dict(features)
    bad[names[2]] = (features[names[2]][0], features[names[2]][1][:, :64])
    with pytest.raises(tessera.InputError, match=r"descriptors of width 64, where "
                                                 r"features\['0000.jpg'\] has width 128"):
        tessera.import_features(tmp_path / "width", bad, images=images, manifest=MANIFEST)

    output = tmp_path / "ws"
    tessera.import_features(output, features, images=images, manifest=MANIFEST)
    count = len(features[names[1]][0])
    with pytest.raises(tessera.InputError,
                       match=rf"matches\[\('0000.jpg', '0001.jpg'\)\] row 1: keypoint index "
                             rf"{count} of '0001.jpg' is out of range"):
        tessera.import_matches(output, {(names[0], names[1]): [[0, 0], [1, count]]},
                               manifest=MANIFEST)
    with pytest.raises(tessera.InputError, match=r"no image 'nowhere.jpg' in workspace"):
        tessera.import_matches(output, {(names[0], "nowhere.jpg"): [[0, 0]]}, manifest=MANIFEST)
    with pytest.raises(TypeError, match=r"matches keys must be \(name1, name2\) tuples"):
        tessera.import_matches(output, {names[0]: [[0, 0]]})
