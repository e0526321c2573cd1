"""tessera.bench against `tessera bench --json` on the same images and manifests."""

import json
import os
import pathlib
import re
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


def test_bench_names_colmap_as_the_cli_does(sample, tmp_path):
    """colmap= is --colmap (a path or a list), colmap_mapper_only= is --colmap-mapper-only:
    a binary that is not there is refused before any row runs, naming it and the keyword's
    flag, as `tessera bench --colmap` refuses it."""
    images, manifest, _ = sample
    missing = tmp_path / "no_colmap"
    for colmap in (missing, [missing], [str(missing)]):
        with pytest.raises(tessera.InputError,
                           match=r"no_colmap: no such file \(named by --colmap\)"):
            tessera.bench(images=images, manifests=[manifest], output=tmp_path / "x",
                          colmap=colmap, colmap_mapper_only=True)
        assert not (tmp_path / "x" / "tessera" / "manifest").exists(), "a row ran before the check"
    with pytest.raises(TypeError, match="colmap"):
        tessera.bench(images=images, manifests=[manifest], output=tmp_path / "x", colmap=[1])
    with pytest.raises(TypeError, match="colmap_mapper_only"):
        tessera.bench(images=images, manifests=[manifest], output=tmp_path / "x",
                      colmap_mapper_only="yes")


def test_bench_colmap_mapper_only(sample, tmp_path):
    """COLMAP 4 (../shared/anchors/colmap-4) named by colmap=, its mappers alone on the
    Tessera row's database: a row per mapper, labelled with COLMAP's version, beside the
    Tessera row, as `tessera bench --colmap PATH --colmap-mapper-only` gives."""
    colmap4 = (pathlib.Path(os.environ["TESSERA_SOURCE_DIR"]) /
               "../shared/anchors/colmap-4/bin/colmap")
    if not os.access(colmap4, os.X_OK) or subprocess.run(
            [colmap4, "-h"], capture_output=True, check=False).returncode != 0:
        pytest.skip(f"{colmap4} does not run (scripts/install_dependencies.sh)")
    images, manifest, _ = sample
    rows = tessera.bench(images=images, manifests=[manifest], output=tmp_path / "out",
                         colmap=colmap4, colmap_mapper_only=True, threads=2)
    names = [row["manifest"] for row in rows]
    assert names[0] == "manifest" and len(rows) == 3, names
    assert re.fullmatch(r"colmap-4\.[^-]+-global", names[1]), names
    assert re.fullmatch(r"colmap-4\.[^-]+-incremental", names[2]), names
    for row in rows:
        assert row["exit_code"] == 0 and row["num_registered"] == 11, row
