"""Fixtures of the Python module's tests: the sample (examples/fountain-P11-small),
downscaled to 512 px as the end-to-end tests do, run once by the `tessera` CLI with ORB
for speed; the tests compare the module against that run. ctest sets the variables
(python/CMakeLists.txt)."""

import hashlib
import json
import os
import pathlib
import subprocess

import pytest

# The end-to-end tests' fast recipe (tests/end_to_end/workspace_test.sh).
MANIFEST = {
    "pipeline": {
        "detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
        "pair_selector": {"plugin": "exhaustive"},
        "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": True}},
        "bundle_adjuster": {"plugin": "ceres"},
        "exporters": [{"plugin": "colmap_binary"}],
    },
    "camera": {"model": "SIMPLE_RADIAL", "single_camera": True},
    "verification": {"max_error_px": 4.0, "min_num_inliers": 15},
}


def model_digests(output):
    """SHA-256 of each sparse/N/*.bin of a workspace, by relative path."""
    output = pathlib.Path(output)
    return {
        str(path.relative_to(output)): hashlib.sha256(path.read_bytes()).hexdigest()
        for path in sorted(output.glob("sparse/*/*.bin"))
    }


@pytest.fixture(scope="session")
def sample(tmp_path_factory):
    """(images, manifest file, CLI workspace) of the downscaled sample."""
    root = tmp_path_factory.mktemp("sample")
    source = pathlib.Path(os.environ["TESSERA_SOURCE_DIR"])
    images = root / "images"
    subprocess.run(
        [os.environ["TESSERA_TEST_DOWNSCALE"], source / "examples/fountain-P11-small/images",
         images, "512", "90"], check=True, capture_output=True)
    manifest = root / "manifest.json"
    manifest.write_text(json.dumps(MANIFEST))
    output = root / "cli"
    subprocess.run(
        [os.environ["TESSERA_TEST_EXECUTABLE"], "run", "--images", images, "--output", output,
         "--manifest", manifest, "--threads", "2", "-q"], check=True)
    assert model_digests(output), "the CLI wrote no model"
    return images, manifest, output
