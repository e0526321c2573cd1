"""examples/python/pycolmap_style.py, a pycolmap user's script, runs on the sample's
workspace (and its stages on the downscaled images), and its calls and counts are
docs/python.md's table; mypy --strict passes on examples/python/ with the package's stubs."""

import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

import tessera

SOURCE = pathlib.Path(os.environ["TESSERA_SOURCE_DIR"])


def documented_rows():
    """{pycolmap call: 'same' or 'differs'} from docs/python.md's table."""
    rows = {}
    for line in (SOURCE / "docs" / "python.md").read_text().splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if len(cells) == 3 and cells[0] != "pycolmap" and re.match(r"(same|differs)\b", cells[2]):
            rows[cells[0].strip("`")] = re.match(r"(same|differs)", cells[2]).group(1)
    return rows


def test_the_pycolmap_style_script_runs_as_the_table_says(sample, tmp_path):
    images, manifest, output = sample
    package_parent = pathlib.Path(tessera.__file__).resolve().parent.parent
    result = subprocess.run(
        [sys.executable, SOURCE / "examples/python/pycolmap_style.py", "--workspace", output,
         "--images", images, "--manifest", manifest],
        env=dict(os.environ, PYTHONPATH=str(package_parent)), cwd=tmp_path,
        capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # the stages' log stays in logging
    lines = result.stdout.splitlines()
    ran = {line[9:]: line[:8].strip() for line in lines[:-1]}
    assert ran == documented_rows()
    same = sum(kind == "same" for kind in ran.values())
    assert lines[-1] == (f"{same} calls run unchanged, {len(ran) - same} need a documented "
                         "difference")
    text = (SOURCE / "docs" / "python.md").read_text()
    assert f"**{same} calls run unchanged, {len(ran) - same} need the documented difference**" in (
        text)


@pytest.mark.skipif(shutil.which("mypy") is None, reason="mypy is not installed (Debian: mypy)")
def test_mypy_strict_passes_on_the_examples(tmp_path):
    package_parent = pathlib.Path(tessera.__file__).resolve().parent.parent
    result = subprocess.run(
        ["mypy", "--strict", "--no-incremental", "--cache-dir", str(tmp_path),
         str(SOURCE / "examples" / "python")],
        env=dict(os.environ, MYPYPATH=str(package_parent)), capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    # The package itself is checked too (it is on MYPYPATH, not installed): an error in
    # the stubs or tessera/__init__.py fails here.
    bad = tmp_path / "bad.py"
    bad.write_text("import tessera\ntessera.Reconstruction().project('one', 2, 3)\n")
    result = subprocess.run(["mypy", "--strict", "--no-incremental", "--cache-dir",
                             str(tmp_path), str(bad)],
                            env=dict(os.environ, MYPYPATH=str(package_parent)),
                            capture_output=True, text=True)
    assert result.returncode == 1 and "project" in result.stdout, result.stdout
