"""tessera.bench against `tessera bench --json` on the same images and manifests."""

import json
import os
import subprocess

import pytest

import tessera
from conftest import MANIFEST

# Figures of the runs themselves, the same whoever started them.
COMPARED = ("manifest", "plugins", "exit_code", "extract_shared_with", "num_pairs",
            "pairs_per_selector", "num_verified_pairs", "num_images", "num_registered",
            "num_models", "num_points3D", "mean_track_length", "mean_reprojection_error_px")


def test_bench_rows_are_the_cli_rows(sample, tmp_path):
    images, manifest, _ = sample
    window = json.loads(json.dumps(MANIFEST))
    window["pipeline"]["pair_selector"] = {"plugin": "window", "options": {"window": 3}}
    (tmp_path / "window.json").write_text(json.dumps(window))
    manifests = [manifest, tmp_path / "window.json"]
    rows = tessera.bench(images=images, manifests=manifests, output=tmp_path / "py", threads=2)
    subprocess.run([os.environ["TESSERA_TEST_EXECUTABLE"], "bench", "--images", images,
                    "--output", tmp_path / "cli", "--json", tmp_path / "cli.json", "--threads",
                    "2", *manifests], check=True, capture_output=True)
    cli_rows = json.loads((tmp_path / "cli.json").read_text())["rows"]
    assert len(rows) == 2
    assert [{key: row[key] for key in COMPARED} for row in rows] == \
        [{key: row[key] for key in COMPARED} for row in cli_rows]
    assert rows[0]["num_pairs"] == 55 and rows[1]["num_pairs"] < 55
    # The second row started from the first one's features (the same detector).
    assert rows[1]["extract_shared_with"] == "manifest"
    with pytest.raises(tessera.InputError, match="no_such.json"):
        tessera.bench(images=images, manifests=[tmp_path / "no_such.json"], output=tmp_path / "x")
