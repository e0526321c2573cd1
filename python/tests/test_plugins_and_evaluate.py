"""tessera.plugins() and tessera.evaluate() against what the CLI prints."""

import json
import os
import subprocess

import pytest

import tessera


def cli_json(*arguments):
    result = subprocess.run([os.environ["TESSERA_TEST_EXECUTABLE"], *map(str, arguments)],
                            check=True, capture_output=True, text=True)
    return json.loads(result.stdout)


def test_plugins_lists_what_the_cli_lists_with_default_options():
    listed = tessera.plugins()
    printed = cli_json("plugins", "--json")
    assert listed["abi_version"] == printed["abi_version"]
    assert listed["search_paths"] == printed["search_paths"]
    without_options = [{k: v for k, v in plugin.items() if k not in ("options", "options_error")}
                       for plugin in listed["plugins"]]
    assert without_options == printed["plugins"]
    by_name = {plugin["name"]: plugin for plugin in listed["plugins"]}
    assert {"orb", "sift", "brute_force", "exhaustive", "ceres", "colmap_binary"} <= set(by_name)
    assert by_name["orb"]["kind"] == "detector"
    assert by_name["orb"]["options"]["max_num_features"] > 0
    assert by_name["brute_force"]["options"]["ratio"] == pytest.approx(0.8)


def test_plugin_options_is_what_tessera_plugins_name_prints():
    for name in ("sift", "incremental", "ply"):
        described = tessera.plugin_options(name)
        assert described == cli_json("plugins", name, "--json")
        assert described["name"] == name
        assert described["options"], name
    sift = {option["name"]: option for option in tessera.plugin_options("sift")["options"]}
    assert sift["max_num_features"]["type"] == "integer"
    assert sift["max_num_features"]["default"] == tessera.plugins()["plugins"][
        [p["name"] for p in tessera.plugins()["plugins"]].index("sift")]["options"][
            "max_num_features"]
    assert sift["root_sift"]["type"] == "boolean" and sift["root_sift"]["help"]
    with pytest.raises(tessera.InputError, match="no plugin 'sfit' on the plugin path; did you "
                                                 "mean 'sift'"):
        tessera.plugin_options("sfit")
    with pytest.raises(TypeError, match="name must be a str"):
        tessera.plugin_options(3)  # type: ignore[arg-type]


def test_evaluate_gives_the_figures_of_tessera_eval(sample, tmp_path):
    _, _, output = sample
    model = output / "sparse" / "0"
    # The model against itself as ground truth: every figure as the CLI prints it.
    figures = tessera.evaluate(model, model)
    assert figures == cli_json("eval", model, model, "--json")
    assert figures["registered"] == figures["total"] == len(tessera.Reconstruction(model).images)
    assert figures["pos_mean"] < 1e-9
    empty = tmp_path / "no_ground_truth"
    empty.mkdir()
    with pytest.raises(tessera.InputError, match="no_ground_truth"):
        tessera.evaluate(model, empty)
