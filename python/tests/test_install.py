"""The module installed with `cmake --install` imports in a fresh interpreter from the
prefix alone, and finds the prefix's plugins and manifests, not the build tree's."""

import json
import os
import pathlib
import subprocess
import sys

import tessera


def test_the_installed_module_imports_and_finds_its_prefix(sample, tmp_path):
    _, _, output = sample
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", os.environ["TESSERA_BUILD_DIR"], "--prefix", prefix],
                   check=True, capture_output=True)
    # The same folder below the prefix as below the build folder.
    build_dir = pathlib.Path(os.environ["TESSERA_BUILD_DIR"]).resolve()
    # tessera/__init__.py: the folder above the package's is the one on the path.
    module_dir = prefix / pathlib.Path(tessera.__file__).resolve().parent.parent.relative_to(
        build_dir)
    script = f"""
import json, tessera
plugins = tessera.plugins()
model = tessera.Reconstruction({str(output / "sparse" / "0")!r})
print(json.dumps({{"file": tessera.__file__, "search_paths": plugins["search_paths"],
                  "usable": sum(p["usable"] for p in plugins["plugins"]),
                  "images": len(model.images)}}))
"""
    environment = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    environment["PYTHONPATH"] = str(module_dir)
    result = subprocess.run([sys.executable, "-c", script], env=environment, capture_output=True,
                            text=True, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    found = json.loads(result.stdout)
    assert pathlib.Path(found["file"]).parent.parent == module_dir
    # Only the prefix's bundled folder (lib/ or lib64/ as GNUInstallDirs names it).
    [search_path] = found["search_paths"]
    assert pathlib.Path(search_path).parent.parent.parent == prefix
    assert search_path.endswith("/tessera/plugins")
    assert found["usable"] == sum(p["usable"] for p in tessera.plugins()["plugins"])
    assert found["images"] == len(tessera.Reconstruction(output / "sparse" / "0").images)
