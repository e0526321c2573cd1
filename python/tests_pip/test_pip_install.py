"""`pip install .` into a fresh venv (system site packages for Debian's numpy, no network,
no build isolation) installs the package, its plugins, recipes and CLI: the package
imports from another folder, its __version__ is the CLI's, and a small run works. The
install reuses the developer's build folder (TESSERA_PIP_BUILD_DIR), so the test costs
the install, not a second build; it prints how long the install took."""

import json
import os
import pathlib
import subprocess
import sys
import time

SOURCE = pathlib.Path(os.environ["TESSERA_SOURCE_DIR"])
FAST = {
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


def test_pip_install_into_a_fresh_venv(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", venv], check=True)
    environment = {key: value for key, value in os.environ.items()
                   if key not in ("PYTHONPATH", "TESSERA_PLUGIN_PATH")}
    environment.setdefault("CCACHE_BASEDIR", str(SOURCE))
    environment["PIP_NO_INDEX"] = "1"  # offline: nothing from a package index
    started = time.monotonic()
    install = subprocess.run(
        [venv / "bin" / "pip", "install", "--no-build-isolation", "--no-index", "-q", SOURCE],
        env=environment, capture_output=True, text=True)
    seconds = time.monotonic() - started
    assert install.returncode == 0, install.stdout[-4000:] + install.stderr[-4000:]
    print(f"\npip install took {seconds:.1f} s")

    # From another folder, with nothing on PYTHONPATH: the venv's own package.
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    images = tmp_path / "images"
    subprocess.run([os.environ["TESSERA_TEST_DOWNSCALE"],
                    SOURCE / "examples/fountain-P11-small/images", images, "512", "90"],
                   check=True, capture_output=True)
    for extra in sorted(images.iterdir())[6:]:
        extra.unlink()  # six images: a small run
    script = f"""
import json, tessera
summary = tessera.run(images={str(images)!r}, output="out", manifest={FAST!r}, threads=2)
plugins = tessera.plugins()
print(json.dumps({{"version": tessera.__version__, "file": tessera.__file__,
                  "search_paths": plugins["search_paths"],
                  "registered": summary["map"]["num_registered"],
                  "points": tessera.Reconstruction("out/sparse/0").num_points3D()}}))
"""
    result = subprocess.run([venv / "bin" / "python", "-c", script], cwd=elsewhere,
                            env=environment, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # the run's log went to logging, which prints nothing
    found = json.loads(result.stdout)
    assert pathlib.Path(found["file"]).is_relative_to(venv)
    assert [pathlib.Path(path).resolve() for path in found["search_paths"]] == [
        (venv / "lib" / "tessera" / "plugins").resolve()]
    assert found["registered"] >= 3 and found["points"] > 100

    # The version is the CLI's, both the venv's CLI and the build's.
    for cli in (venv / "bin" / "tessera", os.environ["TESSERA_TEST_EXECUTABLE"]):
        version = subprocess.run([cli, "--version"], capture_output=True, text=True, check=True)
        assert version.stdout.split()[-1] == found["version"]
    quick = subprocess.run([venv / "bin" / "python", "-c",
                            "import tessera; print(tessera.__version__)"],
                           cwd=elsewhere, env=environment, capture_output=True, text=True)
    assert quick.stdout.strip() == found["version"]


def run_setup_without(module):
    """setup.py run by this Python with `module` made unimportable, as in an environment
    that lacks it."""
    script = ("import runpy, sys\n"
              f"sys.modules[{module!r}] = None\n"
              "sys.argv = ['setup.py', '--name']\n"
              "runpy.run_path('setup.py', run_name='__main__')\n")
    return subprocess.run([sys.executable, "-c", script], cwd=SOURCE, capture_output=True,
                          text=True, timeout=60)


def test_a_python_without_numpy_or_wheel_is_stopped_before_the_build():
    for module in ("numpy", "wheel"):
        result = run_setup_without(module)
        assert result.returncode != 0, module
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1, result.stderr
        assert f"has no `{module}`" in lines[0] and "docs/python.md" in lines[0]
    # Both present: setup.py gets as far as answering --name, without building.
    result = subprocess.run([sys.executable, "setup.py", "--name"], cwd=SOURCE,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and result.stdout.strip().splitlines()[-1] == "tessera"
