"""An unchanged map is kept: tessera.run and tessera.map say so in the summary's
'kept', leave the model's files as they were, and map again once an option changes."""

import copy
import json
import shutil

import tessera
from conftest import MANIFEST, model_digests


def test_an_unchanged_map_is_kept_and_a_changed_one_mapped_again(sample, tmp_path):
    images, manifest, _ = sample
    output = tmp_path / "py"
    first = tessera.run(images=images, output=output, manifest=manifest, threads=2)
    assert first["map"]["kept"] is False
    digests = model_digests(output)
    mapping_summary = (output / "mapping_summary.json").read_bytes()

    again = tessera.run(images=images, output=output, manifest=manifest, threads=2)
    assert again["map"]["kept"] is True
    assert again["map"]["images_per_model"] == first["map"]["images_per_model"]
    assert again["map"]["num_registered"] == first["map"]["num_registered"]
    assert model_digests(output) == digests
    assert (output / "mapping_summary.json").read_bytes() == mapping_summary
    assert json.loads((output / "run_summary.json").read_text())["map"]["kept"] is True

    mapped = tessera.map(output=output, manifest=manifest, threads=2)
    assert mapped["kept"] is True
    assert model_digests(output) == digests

    changed = copy.deepcopy(MANIFEST)
    changed["pipeline"]["mapper"] = {"plugin": "incremental", "options": {"max_reg_trials": 4}}
    remapped = tessera.map(output=output, manifest=changed, threads=2)
    assert remapped["kept"] is False
    assert remapped["num_models"] >= 1
    assert mapping_summary != (output / "mapping_summary.json").read_bytes()


def test_the_cli_model_is_kept_by_python(sample, tmp_path):
    images, manifest, cli_output = sample
    output = tmp_path / "copy"
    shutil.copytree(cli_output, output)
    digests = model_digests(output)
    mapped = tessera.map(output=output, manifest=manifest, threads=2)
    assert mapped["kept"] is True
    assert model_digests(output) == digests
