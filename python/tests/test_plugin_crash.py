"""A plugin that crashes during a stage (the stages run in a child process): the call
raises tessera.PluginCrashError naming the plugin and the image, the interpreter lives
on, and the calls that follow behave as the CLI's reruns do (the crash reported, the
image that crashed the detector twice skipped), as tests/end_to_end/quarantine_test.sh
checks for the CLI."""

import json
import os
import pathlib

import pytest

import tessera
from conftest import MANIFEST


def crash_manifest(width):
    """The fast recipe, with a detector that crashes (SIGSEGV) on images `width` wide."""
    manifest = json.loads(json.dumps(MANIFEST))
    manifest["pipeline"]["detector"] = {
        "plugin": "failing_detector", "options": {"fail": "segv", "on_width": width}}
    return manifest


@pytest.fixture
def failing_plugins(monkeypatch):
    """The test plugins that fail on request (tests/plugins/broken_plugins.cc)."""
    folder = pathlib.Path(os.environ["TESSERA_BUILD_DIR"]) / "test_plugins" / "failing"
    monkeypatch.setenv("TESSERA_PLUGIN_PATH", str(folder))


def test_a_crashing_detector_raises_and_is_quarantined_as_in_the_cli(
        sample, tmp_path, failing_plugins, caplog):
    images, _, _ = sample
    # 0000.jpg 512 px wide, 0001.jpg 1024 px: the detector crashes on the second only.
    two = tmp_path / "two"
    two.mkdir()
    (two / "0000.jpg").write_bytes((images / "0000.jpg").read_bytes())
    source = pathlib.Path(os.environ["TESSERA_SOURCE_DIR"]) / "examples/fountain-P11-small/images"
    (two / "0001.jpg").write_bytes((source / "0001.jpg").read_bytes())
    output = tmp_path / "out"
    manifest = crash_manifest(1024)
    calls = []
    for _ in range(2):
        with pytest.raises(tessera.PluginCrashError) as raised:
            tessera.extract(images=two, output=output, manifest=manifest, threads=1,
                            progress=lambda *call: calls.append(call))
        assert str(raised.value).startswith(
            "plugin 'failing_detector' crashed (SIGSEGV) while detecting image 0001.jpg; "
            "what was finished is kept and the same call resumes"), str(raised.value)
    assert raised.value.exit_code == 4
    assert calls == [("extract", 1, 2)]  # the first call's 0000.jpg; the second's reused
    assert isinstance(raised.value, tessera.Error)
    # The third call, as the CLI's third run: the image that crashed the detector twice
    # is skipped, the other was kept from the first call.
    caplog.clear()
    with caplog.at_level("INFO", logger="tessera"):
        summary = tessera.extract(images=two, output=output, manifest=manifest, threads=1)
    assert ("tessera.extract", 30,
            "extract: skipping 0001.jpg: it crashed detector 'failing_detector' twice") in (
        caplog.record_tuples)
    assert summary["num_images"] == 2
    assert summary["num_reused"] == 1
    assert summary["num_detected"] == 0
    assert summary["num_quarantined"] == 1  # counted, not lost among the 0 failed
    assert summary["num_failed"] == 0
    history = (output / "plugin_crashes.tsv").read_text().splitlines()
    # Each record: signal, plugin, stage, subject, then the plugin's build (version, file
    # hash, options digest), which keys the quarantine.
    assert [line.split("\t")[:4] for line in history] == \
        [["SIGSEGV", "failing_detector", "detect", "image 0001.jpg"]] * 2
    assert all(len(line.split("\t")) == 7 for line in history), history


def test_the_interpreter_runs_normal_stages_after_a_crash(sample, tmp_path, failing_plugins):
    images, _, _ = sample
    with pytest.raises(tessera.PluginCrashError, match="failing_detector"):
        tessera.extract(images=images, output=tmp_path / "crash", manifest=crash_manifest(0),
                        threads=1)
    summary = tessera.extract(images=images, output=tmp_path / "fine", manifest=MANIFEST,
                              threads=2)
    assert summary["num_detected"] == 11



def test_an_exporter_that_crashes_raises_naming_it(sample, tmp_path, failing_plugins):
    _, _, cli_output = sample
    with pytest.raises(tessera.PluginCrashError,
                       match=r"^plugin 'failing_exporter' crashed \(SIGSEGV\) while exporting"):
        tessera.export(model=cli_output / "sparse" / "0", format="failing_exporter",
                       output=tmp_path / "x", options={"fail": "segv"})
    summary = tessera.export(model=cli_output / "sparse" / "0", format="colmap_text",
                             output=tmp_path / "text")
    assert summary["num_points3D"] == len(tessera.Reconstruction(cli_output / "sparse" / "0")
                                          .points3D)
