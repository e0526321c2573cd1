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


# What mypy --strict must refuse, by line: the pose is typed (tessera.Rigid3d), not Any.
MISUSES = {
    4: ("pose(np.zeros(3))", '"Rigid3d" not callable'),
    5: ("pose * 2", 'No overload variant of "__mul__" of "Rigid3d" matches argument type "int"'),
    6: ("R, t = pose", '"Rigid3d" object is not iterable'),
    7: ("pose.translation = np.zeros(3)",
        'Property "translation" defined in "Rigid3d" is read-only'),
    8: ("tessera.Reconstruction().transform(pose)",
        'has incompatible type "Rigid3d"; expected "Sim3d"'),
    9: ("tessera.Sim3d() * pose", 'No overload variant of "__mul__" of "Sim3d"'),
    10: ("tessera.Reconstruction().project('one', 2, 3)", 'Too many arguments for "project"'),
}


def run_mypy(tmp_path, *paths):
    package_parent = pathlib.Path(tessera.__file__).resolve().parent.parent
    return subprocess.run(
        ["mypy", "--strict", "--no-incremental", "--cache-dir", str(tmp_path / "cache"),
         *map(str, paths)], env=dict(os.environ, MYPYPATH=str(package_parent)),
        capture_output=True, text=True)


@pytest.mark.skipif(shutil.which("mypy") is None,
                    reason="mypy is not installed (Debian: mypy, scripts/install_dependencies.sh)")
def test_mypy_strict_passes_on_the_examples_and_refuses_a_misused_pose(tmp_path):
    result = run_mypy(tmp_path, SOURCE / "examples" / "python")
    assert result.returncode == 0, result.stdout + result.stderr
    # The package itself is checked too (it is on MYPYPATH, not installed): an error in
    # the stubs or tessera/__init__.py fails here.
    bad = tmp_path / "bad.py"
    bad.write_text("import numpy as np\nimport tessera\n"
                   "pose = tessera.Reconstruction('model').images[1].cam_from_world\n" +
                   "".join(f"{line}\n" for line, _ in MISUSES.values()))
    result = run_mypy(tmp_path, bad)
    assert result.returncode == 1, result.stdout
    errors = {}
    for line in result.stdout.splitlines():
        match = re.match(r"bad\.py:(\d+): error: (.*)", line.replace(str(bad), "bad.py"))
        if match:
            errors.setdefault(int(match.group(1)), []).append(match.group(2))
    assert sorted(errors) == sorted(MISUSES), result.stdout
    for number, (_, expected) in MISUSES.items():
        assert any(expected in error for error in errors[number]), (number, errors[number])
