"""The module as a Python package (issue 51): signatures inspect can read, TypeError
naming the argument, pickling and copies, reprs, KeyError naming the id, project of one
point, pycolmap's names, Database images with keypoints, logging through `logging`
(nothing printed by default), hints phrased as Python calls, a dict manifest where a
path goes, and an export interrupted after it had finished."""

import copy
import inspect
import logging
import pickle
import pickletools

import numpy as np
import pytest

import tessera
from conftest import MANIFEST

CLASSES = (tessera.Camera, tessera.Image, tessera.Point3D, tessera.Reconstruction,
           tessera.Database)


def public_functions():
    """(name, function) of every public function and method the package has."""
    found = [(name, getattr(tessera, name)) for name in tessera.__all__
             if callable(getattr(tessera, name)) and not inspect.isclass(getattr(tessera, name))]
    for cls in CLASSES:
        for name, member in vars(cls).items():
            if ((name.startswith("_") and name != "__init__") or isinstance(member, property)
                    or inspect.isclass(member)):  # the Map classes keep pybind11's own
                continue
            if callable(getattr(cls, name)):
                found.append((f"{cls.__name__}.{name}", getattr(cls, name)))
    return found


@pytest.mark.parametrize("name,function", public_functions(), ids=lambda v: str(v)[:40])
def test_every_public_function_has_a_valid_signature(name, function):
    signature = inspect.signature(function)  # raises "no signature found" without one
    seen_default = False
    for parameter in signature.parameters.values():
        if parameter.kind == parameter.POSITIONAL_OR_KEYWORD:
            assert not (seen_default and parameter.default is parameter.empty), name
            seen_default |= parameter.default is not parameter.empty
    # The docstring's first line is no pybind11 signature, which is not valid Python.
    assert not (function.__doc__ or "").startswith(f"{name.split('.')[-1]}(self: "), name


def test_signatures_name_the_arguments():
    assert list(inspect.signature(tessera.Reconstruction.project).parameters) == [
        "self", "image_id", "points"]
    assert str(inspect.signature(tessera.Reconstruction.write)) == "(self, path, format='binary')"
    run = inspect.signature(tessera.run)
    assert list(run.parameters)[:3] == ["images", "output", "manifest"]
    assert run.parameters["threads"].default == 0


def test_dir_lists_no_pybind11_helper_classes(model):
    for cls in CLASSES:
        assert not [name for name in dir(cls) if "View" in name], dir(cls)
    assert tessera.Image.Map.__qualname__ == "Image.Map"
    # The views still work where they are used.
    assert list(model.images.keys()) == sorted(model.images)
    assert len(list(model.cameras.items())) == len(model.cameras)


def test_version_all_and_stubs():
    assert tessera.__version__.count(".") == 2
    assert set(tessera.__all__) <= set(dir(tessera))
    package = __import__("pathlib").Path(tessera.__file__).parent
    assert (package / "py.typed").is_file() and (package / "_tessera.pyi").is_file()


@pytest.mark.parametrize("call,argument", [
    (lambda: tessera.plugins(manifest=42), "manifest"),
    (lambda: tessera.plugins(manifest=[1, 2]), "manifest"),
    (lambda: tessera.run(images=3.5, output="x"), "images"),
    (lambda: tessera.run(images="x", output=None), "output"),
    (lambda: tessera.extract(images="x", output="y", threads="2"), "threads"),
    (lambda: tessera.map(output="y", progress=5), "progress"),
    (lambda: tessera.export(model="m", format=1, output="o"), "format"),
    (lambda: tessera.bench(images="i", manifests="m.json"), "manifests"),
    (lambda: tessera.evaluate(model=1, ground_truth="g"), "model"),
])
def test_wrong_argument_types_raise_type_error_naming_the_argument(call, argument):
    with pytest.raises(TypeError, match=rf"\(\): {argument}"):
        call()


def test_a_dict_manifest_works_where_a_path_does():
    listed = tessera.plugins(manifest=MANIFEST)
    assert listed["plugins"] and listed == tessera.plugins()
    with pytest.raises(tessera.InputError, match="plugin_paths"):
        tessera.plugins(manifest={"plugin_paths": [42]})


@pytest.fixture
def model(sample):
    return tessera.Reconstruction(sample[2] / "sparse" / "0")


def state(model):
    return (sorted((i, im.name, im.cam_from_world.matrix().tobytes(), im.keypoints.tobytes(),
                    im.point3D_ids.tobytes()) for i, im in model.images.items()),
            sorted((i, c.model, c.params.tobytes()) for i, c in model.cameras.items()),
            sorted((i, p.xyz.tobytes(), p.color.tobytes(), p.error, p.track.tobytes())
                   for i, p in model.points3D.items()))


def test_pickle_copy_and_deepcopy_keep_every_value(model, tmp_path):
    for other in (pickle.loads(pickle.dumps(model)), copy.copy(model), copy.deepcopy(model)):
        assert other is not model and state(other) == state(model)
    image = next(iter(model.images.values()))
    for value in (image, model.cameras[image.camera_id], next(iter(model.points3D.values()))):
        for other in (pickle.loads(pickle.dumps(value)), copy.copy(value), copy.deepcopy(value)):
            assert type(other) is type(value) and repr(other) == repr(value)
    pose = pickle.loads(pickle.dumps(image.cam_from_world))
    np.testing.assert_array_equal(pose.rotation.quat, image.cam_from_world.rotation.quat)
    again = pickle.loads(pickle.dumps(image))
    np.testing.assert_array_equal(again.keypoints, image.keypoints)
    np.testing.assert_array_equal(again.cam_from_world.matrix(), image.cam_from_world.matrix())
    # A copy is independent: moving its point leaves the original's.
    other = copy.deepcopy(model)
    point3D_id = next(iter(other.points3D))
    other.points3D[point3D_id].xyz = [1.0, 2.0, 3.0]
    assert not np.array_equal(model.points3D[point3D_id].xyz, [1.0, 2.0, 3.0])
    # The unpickled model writes what the original does.
    pickle.loads(pickle.dumps(model)).write(tmp_path / "copy")
    assert tessera.Reconstruction(tmp_path / "copy").num_points3D() == model.num_points3D()


def test_pickles_call_a_checking_factory_never_a_bare_new(model):
    """A pickle that called Camera.__new__ and then failed to reach __setstate__ would leave
    an object with no C++ value behind it; each pickle names a factory that checks."""
    image = next(iter(model.images.values()))
    values = {"reconstruction_from_state": model, "image_from_state": image,
              "camera_from_state": model.cameras[image.camera_id],
              "point3D_from_state": next(iter(model.points3D.values()))}
    for factory, value in values.items():
        opcodes = [op.name for op, _, _ in pickletools.genops(pickle.dumps(value))]
        assert "NEWOBJ" not in opcodes and "NEWOBJ_EX" not in opcodes, (factory, opcodes)
        assert b"tessera._pickle" in pickle.dumps(value) and factory.encode() in pickle.dumps(value)
    with pytest.raises(tessera.InputError, match="unknown camera model 'NOPE'"):
        tessera._tessera._camera_from_state((1, "NOPE", 10, 10, []))


def test_an_empty_reconstruction():
    empty = tessera.Reconstruction()
    assert repr(empty) == "Reconstruction(cameras=0, images=0, points3D=0)"
    assert empty.num_points3D() == 0 and empty.num_reg_images() == 0
    assert state(pickle.loads(pickle.dumps(empty))) == state(empty)
    with pytest.raises(KeyError, match="image_id 1: no such image .the model has none."):
        empty.images[1]


def test_reprs_say_what_the_object_is(model):
    image = model.images[next(iter(model.images))]
    assert repr(image) == (f"Image(image_id={image.image_id}, name={image.name!r}, "
                           f"camera_id={image.camera_id}, num_points3D={image.num_points3D()})")
    camera = model.cameras[image.camera_id]
    assert repr(camera) == (f"Camera(camera_id={camera.camera_id}, model='SIMPLE_RADIAL', "
                            f"width=512, height=342)")
    point = next(iter(model.points3D.values()))
    assert repr(point).startswith("Point3D(xyz=[") and f"track_length={len(point.track)})" in repr(
        point)
    assert "object at 0x" not in repr(image) + repr(camera) + repr(point)


def test_key_error_names_the_id(model):
    last = max(model.images)
    with pytest.raises(KeyError, match=rf"image_id 999: no such image \(ids 1..{last}\)"):
        model.images[999]
    with pytest.raises(KeyError, match="point3D_id 12345678: no such point3D"):
        model.points3D[12345678]
    with pytest.raises(KeyError, match="image_id 999: no such image"):
        model.project(999, np.zeros(3))


def test_project_one_point_or_many(model):
    image_id = next(iter(model.images))
    points = model.points3D_arrays()["xyz"][:5]
    many = model.project(image_id, points)
    assert many.shape == (5, 2)
    one = model.project(image_id, points[2])
    assert one.shape == (2,)
    np.testing.assert_array_equal(one, many[2])
    with pytest.raises(ValueError, match=r"points: expected one \(3,\) point or an \(N, 3\)"):
        model.project(image_id, np.zeros(4))


def test_pycolmap_names(model):
    statistics = model.statistics()
    # COLMAP's (pycolmap's, model_analyzer's): the mean of the points' stored errors.
    errors = model.points3D_arrays()["errors"]
    assert model.compute_mean_reprojection_error() == pytest.approx(
        np.mean(errors[errors != -1]), rel=1e-12)
    # The recompute projects each point into its track's images: the host's figure.
    assert model.compute_mean_reprojection_error_from_scratch() == (
        statistics["mean_reprojection_error"])
    assert model.num_points3D() == len(model.points3D) == statistics["num_points3D"]
    image = model.images[next(iter(model.images))]
    assert model.find_image_with_name(image.name).image_id == image.image_id
    assert model.find_image_with_name("no_such.jpg") is None
    assert f"num_points3D = {len(model.points3D)}" in model.summary()
    pose = image.cam_from_world
    R, t = pose.rotation.matrix(), pose.translation
    with pytest.raises(TypeError):
        R, t = pose  # a Rigid3d, as pycolmap's, is no tuple: it does not unpack
    x, y, z, w = pose.rotation.quat
    assert abs(np.linalg.norm([x, y, z, w]) - 1) < 1e-9
    np.testing.assert_allclose(pose.rotation.matrix(), R, atol=1e-12)
    np.testing.assert_array_equal(pose.translation, t)
    np.testing.assert_allclose(pose.matrix(), np.hstack([R, t[:, None]]))


def test_database_images_have_their_keypoints(sample, model):
    database = tessera.Database(sample[2] / "database.db")
    images = database.images
    for image_id, image in images.items():
        np.testing.assert_array_equal(image.keypoints,
                                      database.keypoints(image_id)[:, :2].astype(np.float64))
        assert image.num_points3D() == 0 and not image.registered
    assert len(images[1].keypoints) == len(model.images[1].keypoints)


def test_stages_log_through_logging_and_print_nothing_by_default(sample, tmp_path, capfd,
                                                                 caplog):
    images = sample[0]
    two = tmp_path / "two"
    two.mkdir()
    for name in ("0000.jpg", "0001.jpg"):
        (two / name).write_bytes((images / name).read_bytes())
    tessera.extract(images=two, output=tmp_path / "quiet", manifest=MANIFEST, threads=1)
    assert capfd.readouterr() == ("", "")  # no handler configured: nothing printed
    caplog.set_level(logging.INFO, logger="tessera")
    tessera.extract(images=two, output=tmp_path / "loud", manifest=MANIFEST, threads=1)
    names = {record.name for record in caplog.records}
    assert "tessera.extract" in names
    assert any("2 images, 2 to detect with 'orb'" in r.getMessage() for r in caplog.records)
    assert capfd.readouterr() == ("", "")
    # The level decides: at WARNING, no info line is emitted.
    caplog.clear()
    caplog.set_level(logging.WARNING, logger="tessera")
    tessera.extract(images=two, output=tmp_path / "warn", manifest=MANIFEST, threads=1)
    assert all(record.levelno >= logging.WARNING for record in caplog.records)


def test_the_mean_reprojection_error_averages_the_stored_errors(model):
    copy_ = pickle.loads(pickle.dumps(model))
    stored = copy_.compute_mean_reprojection_error()
    recomputed = copy_.compute_mean_reprojection_error_from_scratch()
    # Moving a point changes the recompute, not the stored errors pycolmap averages.
    for point in list(copy_.points3D.values())[:20]:
        point.xyz = point.xyz + 0.5
    assert copy_.compute_mean_reprojection_error() == stored
    assert copy_.compute_mean_reprojection_error_from_scratch() > recomputed
    assert f"mean_reprojection_error = {stored:.6f}" in copy_.summary()
    assert tessera.Reconstruction().compute_mean_reprojection_error() == 0.0
    assert tessera.Reconstruction().compute_mean_reprojection_error_from_scratch() == 0.0


def test_hints_name_the_python_call(tmp_path):
    from tessera import _hints
    assert _hints.for_python("x: no features; run `tessera extract` (or `tessera run`) "
                             "first") == (
        "x: no features; call tessera.extract() (or tessera.run()) first")
    assert _hints.for_python("run `tessera map --cluster 3` again") == (
        "call tessera.map(cluster=3) again")
    assert "logged on 'tessera.map'" in _hints.for_python("no model (see the warnings above)")
    # Options and steps named as keywords and calls, other CLI commands kept for the shell.
    assert _hints.for_python("kept the 1 model(s) in x (pass --force-map or change an option "
                             "to re-map)") == (
        "kept the 1 model(s) in x (pass force_map=True or change an option to re-map)")
    assert _hints.for_python("x: no workspace database for map; run extract and match "
                             "first") == ("x: no workspace database for map; call "
                                          "tessera.extract(...) and tessera.match(...) first")
    assert _hints.for_python("extract again with --camera-K FILE") == (
        "call tessera.extract(...) again with camera_K=FILE")
    assert _hints.for_python("--rig: partitioned mapping (--cluster, --cluster-shard, "
                             "--hierarchical)") == (
        "rig: partitioned mapping (cluster, cluster_shard, hierarchical)")
    assert _hints.for_python("map --cluster 3: no model") == "tessera.map(cluster=3): no model"
    assert _hints.for_python("run `tessera merge --output x` first") == (
        "run `tessera merge --output x` first")
    with pytest.raises(tessera.InputError) as raised:
        tessera.match(output=tmp_path / "empty", manifest=MANIFEST)
    assert "`tessera " not in str(raised.value), str(raised.value)
    with pytest.raises(tessera.InputError,
                       match=r"call tessera\.extract\(\.\.\.\) and tessera\.match\(\.\.\.\) first"):
        tessera.map(output=tmp_path / "none", manifest=MANIFEST)
    # match made the database of "empty", which holds no images.
    with pytest.raises(tessera.InputError,
                       match=r"has no images; call tessera\.extract\(\.\.\.\) first"):
        tessera.map(output=tmp_path / "empty", manifest=MANIFEST)
    assert _hints.for_python("x: no verified image pairs in the workspace; run match "
                             "first") == ("x: no verified image pairs in the workspace; call "
                                          "tessera.match(...) first")


def test_results_count_quarantined_images_as_their_own(sample, tmp_path):
    # The extract part of every summary has the field (test_plugin_crash counts one).
    summary = tessera.extract(images=sample[0], output=tmp_path, manifest=MANIFEST, threads=2)
    assert summary["num_quarantined"] == 0 and summary["num_detected"] == 11


class InterruptOn(logging.Handler):
    """Raises KeyboardInterrupt, as a Ctrl-C would, on the first record that has `text`."""

    def __init__(self, text):
        super().__init__()
        self.text = text

    def emit(self, record):
        if self.text in record.getMessage():
            self.text = "\0never"
            raise KeyboardInterrupt


def test_an_export_interrupted_once_finished_says_so(sample, tmp_path, caplog):
    model = sample[2] / "sparse" / "0"
    handler = InterruptOn("export: wrote")
    logger = logging.getLogger("tessera.export")
    logger.addHandler(handler)
    caplog.set_level(logging.INFO, logger="tessera")
    try:
        result = tessera.export(model=model, format="colmap_text", output=tmp_path / "text")
    finally:
        logger.removeHandler(handler)
    assert result["num_images"] == tessera.Reconstruction(model).num_reg_images()
    assert ("tessera.export", logging.WARNING,
            "export: interrupted after it had finished; its output is complete") in (
        caplog.record_tuples)
    assert tessera.Reconstruction(tmp_path / "text" / "sparse" / "0").num_points3D() > 0 or (
        any((tmp_path / "text").rglob("points3D.txt")))
