"""tessera.run, extract, match, map and export against the CLI on the same input: the
same model files, a cancel from the progress callback that the same call resumes, and
bad manifests raised as the named exceptions."""

import json
import os
import pathlib
import signal
import subprocess
import sys
import threading
import time

import pytest

import tessera
from conftest import MANIFEST, model_digests


def test_run_gives_the_cli_model(sample, tmp_path):
    images, manifest, cli_output = sample
    calls = []
    summary = tessera.run(images=images, output=tmp_path / "py", manifest=manifest, threads=2,
                          progress=lambda stage, done, total: calls.append((stage, done, total)))
    assert model_digests(tmp_path / "py") == model_digests(cli_output)
    # The summary is run_summary.json, as the CLI writes it.
    written = json.loads((tmp_path / "py" / "run_summary.json").read_text())
    assert summary["map"] == written["map"]
    assert summary["extract"]["num_images"] == 11
    assert {stage for stage, _, _ in calls} >= {"extract", "match", "map"}
    assert ("extract", 11, 11) in calls


def test_stages_one_by_one_with_a_dict_manifest_give_the_cli_model(sample, tmp_path):
    images, _, cli_output = sample
    output = tmp_path / "py"
    extract = tessera.extract(images=images, output=output, manifest=MANIFEST, threads=2)
    assert extract["num_detected"] == 11
    match = tessera.match(output=output, manifest=MANIFEST, threads=2)
    assert match["num_pairs"] == 55
    mapped = tessera.map(output=output, manifest=MANIFEST, threads=2)
    assert mapped["num_models"] >= 1
    assert model_digests(output) == model_digests(cli_output)


def test_camera_per_folder_gives_each_subfolder_its_camera(sample, tmp_path):
    images, _, _ = sample
    folders = tmp_path / "images"
    for k, image in enumerate(sorted(pathlib.Path(images).iterdir())[:6]):
        (folders / ("a" if k % 2 else "b")).mkdir(parents=True, exist_ok=True)
        (folders / ("a" if k % 2 else "b") / image.name).write_bytes(image.read_bytes())
    tessera.extract(images=folders, output=tmp_path / "per_folder", manifest=MANIFEST,
                    threads=2, camera_per_folder=True)
    database = tessera.Database(tmp_path / "per_folder" / "database.db")
    assert len(database.cameras) == 2
    folder_of_camera = {}
    for image in database.images.values():
        folder_of_camera.setdefault(image.camera_id, set()).add(image.name.split("/")[0])
    assert sorted(folder_of_camera.values()) == [{"a"}, {"b"}]
    tessera.extract(images=folders, output=tmp_path / "shared", manifest=MANIFEST, threads=2)
    assert len(tessera.Database(tmp_path / "shared" / "database.db").cameras) == 1


def test_an_exception_in_progress_cancels_and_the_same_call_resumes(sample, tmp_path):
    images, manifest, cli_output = sample
    output = tmp_path / "py"

    def interrupt(stage, done, total):
        if stage == "extract" and done == 4:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        tessera.run(images=images, output=output, manifest=manifest, threads=2,
                    progress=interrupt)
    assert not (output / "run_summary.json").exists()
    summary = tessera.run(images=images, output=output, manifest=manifest, threads=2)
    # The images finished before the cancel are kept, not detected again.
    assert summary["extract"]["num_reused"] >= 4
    assert summary["extract"]["num_detected"] + summary["extract"]["num_reused"] == 11
    assert model_digests(output) == model_digests(cli_output)


def test_bad_manifests_and_arguments_raise_the_named_exception(sample, tmp_path):
    images, _, _ = sample
    bad_option = json.loads(json.dumps(MANIFEST))
    bad_option["pipeline"]["detector"]["options"]["max_num_featurez"] = 5
    with pytest.raises(tessera.InputError, match="pipeline.detector.options.max_num_featurez"):
        tessera.run(images=images, output=tmp_path / "a", manifest=bad_option)
    with pytest.raises(tessera.InputError, match="missing.json"):
        tessera.run(images=images, output=tmp_path / "b", manifest=tmp_path / "missing.json")
    with pytest.raises(tessera.InputError, match="images or videos"):
        tessera.run(output=tmp_path / "c", manifest=MANIFEST)
    with pytest.raises(tessera.InputError, match="database"):
        tessera.map(output=tmp_path / "empty", manifest=MANIFEST)


def test_no_model_raises_no_model_error_naming_the_database(sample, tmp_path):
    images, _, _ = sample
    two = tmp_path / "two"
    two.mkdir()
    for name in ("0000.jpg", "0005.jpg"):
        (two / name).write_bytes((images / name).read_bytes())
    strict = json.loads(json.dumps(MANIFEST))
    strict["verification"]["min_num_inliers"] = 100000
    with pytest.raises(tessera.NoModelError, match="database.db"):
        tessera.run(images=two, output=tmp_path / "out", manifest=strict, threads=2)
    assert tessera.NoModelError.exit_code == 3


def test_export_writes_the_model_with_a_plugin(sample, tmp_path):
    _, _, cli_output = sample
    summary = tessera.export(model=cli_output / "sparse" / "0", format="colmap_text",
                             output=tmp_path / "text")
    assert summary["exporter"] == "colmap_text"
    model = tessera.Reconstruction(cli_output / "sparse" / "0")
    assert summary["num_points3D"] == len(model.points3D)
    exported = tessera.Reconstruction(next((tmp_path / "text").rglob("points3D.txt")).parent)
    assert len(exported.points3D) == len(model.points3D)
    with pytest.raises(tessera.InputError, match="no_such_exporter"):
        tessera.export(model=cli_output / "sparse" / "0", format="no_such_exporter",
                       output=tmp_path / "x")


def test_python_refuses_the_arguments_the_cli_refuses(sample, tmp_path):
    images, _, cli_output = sample
    # `tessera export --model-index -1` is exit 2; the module wrote sparse/-1 (issue 47).
    with pytest.raises(tessera.InputError,
                       match="model_index: Value -1 is not a whole number of at least 0"):
        tessera.export(model=cli_output / "sparse" / "0", format="colmap_binary",
                       output=tmp_path / "neg", model_index=-1)
    assert not (tmp_path / "neg").exists()
    for threads in (-1, 1025):
        with pytest.raises(tessera.InputError, match=f"threads: {threads} is not in 0..1024"):
            tessera.map(output=tmp_path / "t", threads=threads)
        with pytest.raises(tessera.InputError, match=f"threads: {threads} is not in 0..1024"):
            tessera.bench(images=images, manifests=[], output=tmp_path / "b", threads=threads)


@pytest.mark.parametrize("target", ["interpreter", "process_group"])
def test_ctrl_c_while_a_stage_runs_raises_keyboard_interrupt(sample, tmp_path, target):
    # SIGINT to the interpreter (its handler only sets a flag while C++ runs), which
    # cancels the stage's child process; or to the process group, as a terminal's Ctrl-C
    # reaches the child too: the stage is cancelled once, with no exception from the
    # callback, and the interpreter raises KeyboardInterrupt.
    images, manifest, _ = sample
    kill = ("os.kill(os.getpid(), signal.SIGINT)" if target == "interpreter" else
            "os.killpg(os.getpgrp(), signal.SIGINT)")
    script = f"""
import os, signal, sys, tessera
def progress(stage, done, total):
    if stage == "extract" and done == 3:
        {kill}
try:
    tessera.run(images={str(images)!r}, output={str(tmp_path / "out")!r},
                manifest={str(manifest)!r}, threads=2, progress=progress)
except KeyboardInterrupt:
    sys.exit(130)
"""
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            start_new_session=True)
    assert result.returncode == 130, result.stderr
    assert not (tmp_path / "out" / "run_summary.json").exists()
    # The extract stage alone resumes it (the whole run is resumed above).
    summary = tessera.extract(images=images, output=tmp_path / "out", manifest=manifest,
                              threads=2)
    assert summary["num_reused"] >= 3


def _children(pid):
    """The processes whose parent is `pid` (from /proc/*/stat)."""
    found = []
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue  # ended meanwhile
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def _running(pid):
    """Whether `pid` is a process that has not ended (a zombie has)."""
    try:
        return pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.parametrize("signal_number", [signal.SIGTERM, signal.SIGKILL])
def test_the_stage_process_stops_with_an_interpreter_that_is_killed(sample, tmp_path,
                                                                     signal_number):
    # SIGTERM (as a scheduler or `timeout` sends it) or SIGKILL to the interpreter alone,
    # as soon as the stage's process runs: the stage process is cancelled by its death
    # signal and ends (within a generous 20 s: the test waits on the event, never times
    # it) without finishing the run; on its own it would map on and write
    # run_summary.json.
    images, manifest, _ = sample
    script = f"""
import tessera
tessera.run(images={str(images)!r}, output={str(tmp_path / "out")!r},
            manifest={str(manifest)!r}, threads=1)
"""
    interpreter = subprocess.Popen([sys.executable, "-c", script], start_new_session=True,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        children = []
        while not children and interpreter.poll() is None and time.monotonic() < deadline:
            children = _children(interpreter.pid)
            time.sleep(0.01)
        assert children, "no stage process started"
        os.kill(interpreter.pid, signal_number)
        interpreter.wait()
        deadline = time.monotonic() + 20
        while any(_running(child) for child in children) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(_running(child) for child in children), "the stage process outlived it"
        assert not (tmp_path / "out" / "run_summary.json").exists()
    finally:
        if interpreter.poll() is None:
            interpreter.kill()
            interpreter.wait()


def test_the_example_writes_a_png_of_the_sample(sample, tmp_path):
    images, manifest, _ = sample
    script = (pathlib.Path(__file__).resolve().parents[2] / "examples" / "python" /
              "reconstruct_and_plot.py")
    result = subprocess.run(
        [sys.executable, script, "--images", images, "--output", tmp_path / "out", "--manifest",
         manifest, "--threads", "2"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    png = tmp_path / "out" / "top_view.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    import matplotlib.image
    assert matplotlib.image.imread(png).shape[:2] == (960, 960)
    assert "registered in 1 model(s)" in result.stdout


def test_the_full_size_sample_gives_the_reference_models(tmp_path):
    # The default recipe (manifest=None: the default.json beside the module's install)
    # on the 1024x683 sample: the model files whose digests the CLI's
    # sample_model_end_to_end test checks.
    source = pathlib.Path(os.environ["TESSERA_SOURCE_DIR"])
    reference = {}
    for line in (source / "tests/end_to_end/sample_model_digests.txt").read_text().splitlines():
        digest, name = line.split()
        reference[name] = digest
    tessera.run(images=source / "examples/fountain-P11-small/images", output=tmp_path / "out",
                threads=2)
    assert model_digests(tmp_path / "out") == reference


def test_other_python_threads_run_while_a_stage_runs(sample, tmp_path):
    # Between the map stage's first and last report (0 registered images, then all) the
    # mapper runs without the GIL: a Python thread keeps counting meanwhile.
    images, manifest, _ = sample
    counter = {"ticks": 0, "stop": False}

    def count():
        while not counter["stop"]:
            counter["ticks"] += 1
            time.sleep(0.0005)

    ticks_at = {}

    def progress(stage, done, total):
        if stage == "map":
            ticks_at[done] = counter["ticks"]

    thread = threading.Thread(target=count)
    thread.start()
    try:
        tessera.run(images=images, output=tmp_path / "out", manifest=manifest, threads=2,
                    progress=progress)
    finally:
        counter["stop"] = True
        thread.join()
    assert ticks_at[max(ticks_at)] - ticks_at[0] >= 10, ticks_at


def test_mapping_summary_says_how_well_the_calibration_is_pinned(sample, tmp_path):
    """Issue 62: each model's calibration, assessed from its final adjustment (sigma and
    corner shift per refined intrinsic); none assessed where the recipe holds them."""
    images, _, cli_output = sample
    written = json.loads((cli_output / "mapping_summary.json").read_text())
    calibration = written["models"][0]["calibration"]
    assert calibration["assessed"], calibration["reason"]
    assert 0.05 < calibration["observation_sigma_px"] < 2.0
    # The sample's recipe refines the focal length and distortion (SIMPLE_RADIAL's f, k).
    assert [p["parameter"] for p in calibration["parameters"]] == ["f", "k"]
    for parameter in calibration["parameters"]:
        assert parameter["sigma"] > 0 and parameter["corner_shift_px"] > 0
        assert parameter["weak"] == (parameter["corner_shift_px"] > 1.0)
    assert calibration["weak"] == [f"{p['parameter']} of camera {p['camera_id']}"
                                   for p in calibration["parameters"] if p["weak"]]
    held = json.loads(json.dumps(MANIFEST))
    held["pipeline"]["mapper"] = {"plugin": "incremental", "options": {
        "ba_refine_focal_length": False, "ba_refine_extra_params": False}}
    output = tmp_path / "held"
    tessera.run(images=images, output=output, manifest=held, threads=2)
    calibration = json.loads((output / "mapping_summary.json").read_text())["models"][0][
        "calibration"]
    assert not calibration["assessed"] and calibration["reason"] == "no intrinsic was refined"
