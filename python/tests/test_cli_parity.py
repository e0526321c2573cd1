"""The module takes what the CLI takes: every option of run, extract, match, map and export
is a keyword of the Python function (checked against `tessera VERB --help`), a manifest
names a bundled recipe from any folder, and bad arguments raise errors that name them."""

import inspect
import logging
import os
import re
import shutil
import subprocess

import pytest

import tessera
from conftest import MANIFEST

# Options of the CLI with no keyword, and why.
CLI_ONLY = {
    "help": "Python's help()",
    "quiet": "logging's levels (logger 'tessera')",
    "verbose": "logging's levels (logger 'tessera')",
}
# CLI spellings whose keyword differs.
KEYWORD = {"video": "videos", "camera-K": "camera_K"}


def cli_options(verb):
    text = subprocess.run([os.environ["TESSERA_TEST_EXECUTABLE"], verb, "--help"], check=True,
                          capture_output=True, text=True).stdout
    # The options as CLI11 lists them, one per line ("  -h,--help", "  --output TEXT"), not
    # the options that a description mentions ("implies --camera-per-folder").
    options = set(re.findall(r"^  (?:-\w,)?--([A-Za-z][\w-]*)", text, flags=re.M))
    assert "output" in options, text
    return options


@pytest.mark.parametrize("verb", ["run", "extract", "match", "map", "export"])
def test_every_cli_option_is_a_keyword(verb):
    parameters = inspect.signature(getattr(tessera, verb)).parameters
    missing = sorted(option for option in cli_options(verb) - set(CLI_ONLY)
                     if KEYWORD.get(option, option.replace("-", "_")) not in parameters)
    assert not missing, f"tessera.{verb}() lacks the keywords of --{', --'.join(missing)}"


def test_a_manifest_names_a_bundled_recipe_from_any_folder(sample, tmp_path, monkeypatch):
    images, _, _ = sample
    two = tmp_path / "two"
    two.mkdir()
    for name in ("0000.jpg", "0001.jpg"):
        shutil.copy(images / name, two / name)
    monkeypatch.chdir(tmp_path)
    for name in ("fast", "fast.json"):
        summary = tessera.extract(images=two, output=tmp_path / f"ws-{name}", manifest=name,
                                   threads=2)
        assert summary["num_detected"] == 2
    with pytest.raises(tessera.InputError,
                       match=r"fst: cannot read the manifest: no such file, nor a recipe "
                             r"\(the recipes: .*\bfast\b.*\bglobal\b"):
        tessera.extract(images=two, output=tmp_path / "x", manifest="fst")
    # A file of that name in the working folder wins.
    (tmp_path / "fast.json").write_text('{"pipeline": {"detector": {"plugin": "nosuch"}}}')
    with pytest.raises(tessera.InputError, match=re.escape(str(tmp_path / "fast.json"))):
        tessera.extract(images=two, output=tmp_path / "y", manifest="fast.json")
    os.remove(tmp_path / "fast.json")
    assert tessera.plugins(manifest="global")["plugins"]


def test_map_keywords_reach_the_cli_modes(sample, tmp_path, caplog):
    images, manifest, cli_output = sample
    output = tmp_path / "copy"
    shutil.copytree(cli_output, output)
    caplog.set_level(logging.INFO, logger="tessera")
    assert tessera.map(output=output, manifest=manifest, threads=2)["kept"] is True
    kept = [record.getMessage() for record in caplog.records if "kept the" in record.getMessage()]
    assert kept and "pass force_map=True" in kept[0] and "--force-map" not in kept[0], kept
    assert tessera.map(output=output, manifest=manifest, threads=2, force_map=True)["kept"] is False
    with pytest.raises(tessera.InputError, match="no_rig.json"):
        tessera.map(output=output, manifest=manifest, rig=tmp_path / "no_rig.json")
    with pytest.raises(tessera.InputError,
                       match="cluster, cluster_shard and hierarchical: give one at most"):
        tessera.map(output=output, manifest=manifest, cluster=0, hierarchical=True)
    with pytest.raises(tessera.InputError, match=r"rig: partitioned mapping"):
        tessera.map(output=output, manifest=manifest, cluster=0, rig=tmp_path / "rig.json")
    with pytest.raises(tessera.InputError, match="a manifest file or recipe, not a dict"):
        tessera.map(output=output, manifest=MANIFEST, hierarchical=True)
    with pytest.raises(tessera.InputError, match=r"clusters\.json"):
        tessera.map(output=output, manifest=manifest, cluster=0)
    with pytest.raises(tessera.InputError, match=r"cluster_shard '1/x': expected K/N"):
        tessera.map(output=output, manifest=manifest, cluster_shard="1/x")


def test_extract_and_match_take_a_shard(sample, tmp_path):
    images, _, _ = sample
    two = tmp_path / "two"
    two.mkdir()
    for name in ("0000.jpg", "0001.jpg"):
        shutil.copy(images / name, two / name)
    with pytest.raises(tessera.InputError, match=r"shard '2/2': K must be in 0\.\.1"):
        tessera.extract(images=two, output=tmp_path / "s", manifest=MANIFEST, shard="2/2")
    summary = tessera.extract(images=two, output=tmp_path / "s", manifest=MANIFEST, shard="0/2",
                              threads=1)
    assert summary["num_images"] == 2
    assert list((tmp_path / "s" / "shards").iterdir())
    with pytest.raises(TypeError, match=r"match\(\): shard must be a str or None, not int"):
        tessera.match(output=tmp_path / "s", shard=1)


def test_bad_arguments_raise_errors_that_name_them(tmp_path):
    for value in (2**63, 2**64, -2**63):
        with pytest.raises(tessera.InputError, match=rf"threads: {value} is not in 0\.\.1024"):
            tessera.run(images=tmp_path, output=tmp_path / "o", threads=value)
    with pytest.raises(tessera.InputError, match=r"jobs: 2000 is not in 0\.\.1024"):
        tessera.map(output=tmp_path / "o", jobs=2000)
    with pytest.raises(tessera.InputError, match=r"model_index: 4294967296 is not in"):
        tessera.export(model=tmp_path, format="ply", output=tmp_path / "o", model_index=2**32)
    with pytest.raises(TypeError, match=r"run\(\): videos\[1\] must be a path"):
        tessera.run(output=tmp_path / "o", videos=["a.mp4", 3])
    with pytest.raises(TypeError, match=r"bench\(\): manifests\[0\] must be a path"):
        tessera.bench(images=tmp_path, manifests=[1.5])
    with pytest.raises(TypeError, match=r"map\(\): cluster must be an int, not str"):
        tessera.map(output=tmp_path / "o", cluster="0")
    # NaN has no JSON: InputError naming the key, not the JSON parser's message.
    nan = {"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features":
                                                                   float("nan")}}}}
    with pytest.raises(tessera.InputError,
                       match=r"manifest\.pipeline\.detector\.options\.max_num_features: nan"):
        tessera.extract(images=tmp_path, output=tmp_path / "o", manifest=nan)
    with pytest.raises(tessera.InputError, match=r"options\.scale: inf"):
        tessera.export(model=tmp_path, format="ply", output=tmp_path / "o",
                       options={"scale": float("inf")})
    with pytest.raises(TypeError, match=r"manifest\.seed must be a JSON value .* not set"):
        tessera.plugins(manifest={"seed": {1}})
