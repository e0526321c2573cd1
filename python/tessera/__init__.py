"""Tessera, Structure-from-Motion whose every stage is a plugin: COLMAP models, the
pipeline's stages, the workspace database and the plugins, from Python.

The C++ extension is ``tessera._tessera``; this layer gives its functions Python
signatures (``inspect.signature`` and type checkers read them), checks argument types
(TypeError naming the argument), routes the host's log through ``logging`` (logger
"tessera", one child per stage, see tessera/_logging.py), phrases the host's hints as
Python calls, and adds pycolmap's names where the meaning is the same (docs/python.md).
"""

import math
import numbers
import os
import typing
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _hints, _logging, _model_edits, _pycolmap_stages, _tessera
from ._estimators import (estimate_absolute_pose, estimate_essential_matrix,
                          estimate_fundamental_matrix, estimate_homography_matrix,
                          estimate_two_view_geometry)
from ._geometry import Rigid3d, Rotation3d, Sim3d
from ._model_edits import (Point2D, Track, TrackElement, align_reconstructions_via_proj_centers,
                           bundle_adjustment, triangulate_points)
from ._pycolmap_stages import (extract_features, global_mapping, incremental_mapping,
                               match_exhaustive, match_sequential)
from ._tessera import (Camera, Database, Error, Image, InputError, NoModelError, Point3D,
                       PluginCrashError, Reconstruction)
from ._version import __version__

__all__ = [
    "Camera", "Database", "Error", "Image", "InputError", "NoModelError", "Point3D",
    "PluginCrashError", "Point2D", "Reconstruction", "Rigid3d", "Rotation3d", "Sim3d", "Track",
    "TrackElement", "__version__", "adjust", "align", "align_reconstructions_via_proj_centers",
    "bench", "bundle_adjustment", "estimate_absolute_pose", "estimate_essential_matrix",
    "estimate_fundamental_matrix", "estimate_homography_matrix", "estimate_two_view_geometry",
    "evaluate", "export", "extract", "extract_features", "global_mapping", "import_features",
    "import_matches", "incremental_mapping", "map", "match", "match_exhaustive",
    "match_sequential", "plugin_options", "plugins", "register", "run", "triangulate", "triangulate_points",
]

PathLike = Union[str, os.PathLike[str]]
ManifestLike = Union[str, os.PathLike[str], Mapping[str, Any], None]
Progress = Optional[Callable[[str, int, int], object]]


# ---- Argument checks: TypeError naming the argument, before anything runs ----

def _type_name(value: object) -> str:
    return type(value).__name__


def _path(function: str, name: str, value: object) -> Any:
    if value is None:
        raise TypeError(f"{function}(): {name} is required (a path)")
    if isinstance(value, (str, os.PathLike)):
        return value
    raise TypeError(f"{function}(): {name} must be a path (str or os.PathLike), "
                    f"not {_type_name(value)}")


def _optional_path(function: str, name: str, value: object) -> Any:
    return None if value is None else _path(function, name, value)


def _json(function: str, name: str, value: object) -> Any:
    """`value` as JSON would hold it (dicts with str keys, lists, str, finite numbers,
    bool, None); TypeError or InputError naming the key path of what is not."""
    if value is None or isinstance(value, (str, bool)):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        number = float(value)
        if not math.isfinite(number):
            raise InputError(f"{name}: {number} is not a finite number (JSON has no NaN or "
                             f"infinity)")
        return number
    if isinstance(value, Mapping):
        result: Dict[str, Any] = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise TypeError(f"{function}(): {name}: key {key!r} must be a str, not "
                                f"{_type_name(key)}")
            result[key] = _json(function, f"{name}.{key}", item)
        return result
    if isinstance(value, (list, tuple)):
        return [_json(function, f"{name}[{index}]", item) for index, item in enumerate(value)]
    raise TypeError(f"{function}(): {name} must be a JSON value (dict, list, str, number, bool "
                    f"or None), not {_type_name(value)}")


def _manifest(function: str, value: object) -> Any:
    if value is None or isinstance(value, (str, os.PathLike)):
        return value
    if isinstance(value, Mapping):
        return _json(function, "manifest", value)
    raise TypeError(f"{function}(): manifest must be a path or a recipe's name (str or "
                    f"os.PathLike), a dict or None, not {_type_name(value)}")


def _int(function: str, name: str, value: object, low: int = 0, high: int = 1024) -> int:
    """An int in low..high: TypeError naming the argument for another type, InputError
    (as the CLI's exit code 2) for one out of range."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{function}(): {name} must be an int, not {_type_name(value)}")
    if not low <= int(value) <= high:
        raise InputError(f"{name}: {int(value)} is not in {low}..{high}")
    return int(value)


def _number(function: str, name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{function}(): {name} must be a number, not {_type_name(value)}")
    return float(value)


def _optional_int(function: str, name: str, value: object, high: int) -> Optional[int]:
    return None if value is None else _int(function, name, value, 0, high)


def _optional_str(function: str, name: str, value: object) -> Optional[str]:
    if value is None or isinstance(value, str):
        return value
    raise TypeError(f"{function}(): {name} must be a str or None, not {_type_name(value)}")


def _bool(function: str, name: str, value: object) -> bool:
    if not isinstance(value, bool):
        raise TypeError(f"{function}(): {name} must be a bool, not {_type_name(value)}")
    return value


def _paths(function: str, name: str, value: object) -> List[Any]:
    if isinstance(value, (str, bytes, os.PathLike)) or not isinstance(value, Sequence):
        raise TypeError(f"{function}(): {name} must be a list of paths, not {_type_name(value)}")
    return [_path(function, f"{name}[{index}]", item) for index, item in enumerate(value)]


def _progress(function: str, value: object) -> Any:
    if value is not None and not callable(value):
        raise TypeError(f"{function}(): progress must be a callable (stage, done, total) or "
                        f"None, not {_type_name(value)}")
    return value


def _call(function: Callable[..., Any], *arguments: Any, **keywords: Any) -> Any:
    """Calls the extension, its errors' hints phrased as Python calls."""
    try:
        return function(*arguments, **keywords)
    except Error as error:
        if error.args and isinstance(error.args[0], str):
            error.args = (_hints.for_python(error.args[0]),) + error.args[1:]
        raise


# ---- The stages ----

def run(images: Optional[PathLike] = None, output: Optional[PathLike] = None,
        manifest: ManifestLike = None, camera_K: Optional[PathLike] = None,
        masks: Optional[PathLike] = None, videos: Sequence[PathLike] = (), threads: int = 0,
        progress: Progress = None, camera_per_folder: bool = False,
        rig: Optional[PathLike] = None, force_map: bool = False) -> Dict[str, Any]:
    """Every stage, images in, models out (`tessera run`); returns run_summary.json as a
    dict, NoModelError when no model was built. output is required. manifest: a file, a
    bundled recipe by name ("global", "fast", ...) or a dict (default: default.json);
    camera_K: a K.txt file; masks: a folder of IMAGE.png masks; videos: videos to take
    keyframes from instead of images; camera_per_folder: images in different subfolders
    never share a camera; rig: a rig file (implies camera_per_folder); force_map: map even
    when the models in place were made from the same inputs (else they are kept);
    threads: 0 for the manifest's; progress(stage, done, total): an exception from it
    (KeyboardInterrupt) cancels the stage, keeping what was finished for the same call to
    resume. Runs in a child process: a plugin that crashes raises PluginCrashError naming
    it."""
    name = "run"
    return typing.cast(Dict[str, Any], _call(
        _tessera.run, images=_optional_path(name, "images", images),
        output=_path(name, "output", output), manifest=_manifest(name, manifest),
        camera_K=_optional_path(name, "camera_K", camera_K),
        masks=_optional_path(name, "masks", masks), videos=_paths(name, "videos", videos),
        threads=_int(name, "threads", threads), progress=_progress(name, progress),
        camera_per_folder=_bool(name, "camera_per_folder", camera_per_folder),
        rig=_optional_path(name, "rig", rig), force_map=_bool(name, "force_map", force_map)))


def extract(images: Optional[PathLike] = None, output: Optional[PathLike] = None,
            manifest: ManifestLike = None, camera_K: Optional[PathLike] = None,
            masks: Optional[PathLike] = None, videos: Sequence[PathLike] = (),
            threads: int = 0, progress: Progress = None,
            camera_per_folder: bool = False, shard: Optional[str] = None) -> Dict[str, Any]:
    """Ingests images and detects features (`tessera extract`); returns the summary's
    'extract' part (num_failed: images skipped as unreadable; num_quarantined: images
    skipped because they crashed the detector twice). shard: "K/N", only shard K of N,
    into OUTPUT/shards/ (the CLI's `tessera merge` folds the shards into database.db).
    Other arguments as run()'s."""
    name = "extract"
    return typing.cast(Dict[str, Any], _call(
        _tessera.extract, images=_optional_path(name, "images", images),
        output=_path(name, "output", output), manifest=_manifest(name, manifest),
        camera_K=_optional_path(name, "camera_K", camera_K),
        masks=_optional_path(name, "masks", masks), videos=_paths(name, "videos", videos),
        threads=_int(name, "threads", threads), progress=_progress(name, progress),
        camera_per_folder=_bool(name, "camera_per_folder", camera_per_folder),
        shard=_optional_str(name, "shard", shard)))


def match(output: PathLike, manifest: ManifestLike = None, camera_K: Optional[PathLike] = None,
          threads: int = 0, progress: Progress = None, images: Optional[PathLike] = None,
          shard: Optional[str] = None) -> Dict[str, Any]:
    """Matches and verifies the workspace's pairs (`tessera match`); returns the summary's
    'match' part. images: the image folder, where it moved since extract; shard: "K/N",
    only shard K of N's pairs, into OUTPUT/shards/. Other arguments as run()'s."""
    name = "match"
    return typing.cast(Dict[str, Any], _call(
        _tessera.match, output=_path(name, "output", output),
        manifest=_manifest(name, manifest), camera_K=_optional_path(name, "camera_K", camera_K),
        threads=_int(name, "threads", threads), progress=_progress(name, progress),
        images=_optional_path(name, "images", images),
        shard=_optional_str(name, "shard", shard)))


def map(output: PathLike, images: Optional[PathLike] = None, manifest: ManifestLike = None,
        camera_K: Optional[PathLike] = None, threads: int = 0,
        progress: Progress = None, rig: Optional[PathLike] = None, force_map: bool = False,
        cluster: Optional[int] = None, cluster_shard: Optional[str] = None,
        hierarchical: bool = False, jobs: int = 0) -> Dict[str, Any]:
    """Maps a workspace into models (`tessera map`); returns the summary's 'map' part,
    NoModelError when no model was built. At most one of: cluster, only cluster K of
    OUTPUT/clusters.json (the CLI's `tessera partition`), into OUTPUT/clusters/K/;
    cluster_shard, "K/N": the clusters c with c mod N = K; hierarchical: partition, map
    the clusters in a pool of `jobs` processes (0: half the cores; each a `tessera`
    process, so the manifest must be a file or recipe), merge them. Other arguments as
    run()'s."""
    name = "map"
    return typing.cast(Dict[str, Any], _call(
        _tessera.map, output=_path(name, "output", output),
        images=_optional_path(name, "images", images), manifest=_manifest(name, manifest),
        camera_K=_optional_path(name, "camera_K", camera_K),
        threads=_int(name, "threads", threads), progress=_progress(name, progress),
        rig=_optional_path(name, "rig", rig), force_map=_bool(name, "force_map", force_map),
        cluster=_optional_int(name, "cluster", cluster, 2**31 - 1),
        cluster_shard=_optional_str(name, "cluster_shard", cluster_shard),
        hierarchical=_bool(name, "hierarchical", hierarchical),
        jobs=_int(name, "jobs", jobs)))


def import_features(output: PathLike,
                    features: Mapping[str, Tuple[npt.ArrayLike, npt.ArrayLike]],
                    images: Optional[PathLike] = None, manifest: ManifestLike = None,
                    camera_K: Optional[PathLike] = None, threads: int = 0,
                    progress: Progress = None) -> Dict[str, Any]:
    """Imports features made elsewhere (`tessera import --features`), e.g. a learned
    model's: features maps each image's name (relative to images) to (keypoints,
    descriptors), keypoints an N x 2 (x y) or N x 4 (x y scale orientation) array in
    pixels with the centre of the top-left pixel at (0.5, 0.5) (OpenCV's + 0.5),
    descriptors N x D, uint8 or float. Whole numbers 0..255 are stored as they are;
    other values as unit vectors, round(128 + 256 v). The images are ingested as
    extract() ingests them (images: default, the folder the workspace records). Returns
    the import's summary. Arguments as run()'s."""
    name = "import_features"
    if not isinstance(features, Mapping):
        raise TypeError(f"{name}(): features must be a dict {{name: (keypoints, descriptors)}}, "
                        f"not {_type_name(features)}")
    arrays = {}
    for key, value in features.items():
        if not isinstance(key, str):
            raise TypeError(f"{name}(): features keys must be image names (str), not "
                            f"{_type_name(key)}")
        pair: object = value  # checked as what a caller may pass, not as it is typed
        if not isinstance(pair, Sequence) or len(pair) != 2:
            raise TypeError(f"{name}(): features[{key!r}] must be a tuple (keypoints, "
                            f"descriptors), not {_type_name(pair)}")
        arrays[key] = (np.asarray(pair[0]), np.asarray(pair[1]))
    return typing.cast(Dict[str, Any], _call(
        _tessera.import_features, output=_path(name, "output", output), features=arrays,
        images=_optional_path(name, "images", images), manifest=_manifest(name, manifest),
        camera_K=_optional_path(name, "camera_K", camera_K),
        threads=_int(name, "threads", threads), progress=_progress(name, progress)))


def import_matches(output: PathLike, matches: Mapping[Tuple[str, str], npt.ArrayLike],
                   verified: bool = False, manifest: ManifestLike = None, threads: int = 0,
                   progress: Progress = None) -> Dict[str, Any]:
    """Imports matches made elsewhere (`tessera import --matches --match-type raw`):
    matches maps (name1, name2) to an M x 2 array of keypoint indices (row i of name1,
    row j of name2). They are verified geometrically with the manifest's verification
    settings unless verified=True; the pairs become the ones map() maps. Returns the
    import's summary. Arguments as run()'s."""
    name = "import_matches"
    if not isinstance(matches, Mapping):
        raise TypeError(f"{name}(): matches must be a dict {{(name1, name2): M x 2 array}}, "
                        f"not {_type_name(matches)}")
    arrays = {}
    for key, value in matches.items():
        if not (isinstance(key, tuple) and len(key) == 2 and all(isinstance(k, str) for k in key)):
            raise TypeError(f"{name}(): matches keys must be (name1, name2) tuples of str, "
                            f"not {key!r}")
        arrays[key] = np.asarray(value)
    return typing.cast(Dict[str, Any], _call(
        _tessera.import_matches, output=_path(name, "output", output), matches=arrays,
        verified=_bool(name, "verified", verified), manifest=_manifest(name, manifest),
        threads=_int(name, "threads", threads), progress=_progress(name, progress)))


def export(model: PathLike, format: str, output: PathLike, images: Optional[PathLike] = None,
           options: Optional[Mapping[str, Any]] = None, model_index: int = 0,
           masks: Optional[PathLike] = None) -> Dict[str, Any]:
    """Writes a model with an exporter plugin (`tessera export`), in a child process;
    options: a dict. An export cannot stop midway: a Ctrl-C during it returns the result
    once it has finished and logs a warning that says so."""
    name = "export"
    if not isinstance(format, str):
        raise TypeError(f"export(): format must be a str, not {_type_name(format)}")
    if options is not None and not isinstance(options, Mapping):
        raise TypeError(f"export(): options must be a dict or None, not {_type_name(options)}")
    return typing.cast(Dict[str, Any], _call(
        _tessera.export, model=_path(name, "model", model), format=format,
        output=_path(name, "output", output), images=_optional_path(name, "images", images),
        options=None if options is None else _json(name, "options", options),
        model_index=_int(name, "model_index", model_index, -2**31, 2**31 - 1),
        masks=_optional_path(name, "masks", masks)))


def triangulate(output: PathLike, model: Optional[PathLike] = None,
                poses: Optional[PathLike] = None, model_index: int = 0,
                refine_intrinsics: bool = False, manifest: ManifestLike = None,
                threads: int = 0) -> Dict[str, Any]:
    """Triangulates the workspace's verified matches for known poses, every pose held
    (`tessera triangulate`), and writes output/sparse/<model_index>. model: a COLMAP model
    folder (text or binary) with cameras and poses, or poses: a transforms.json (nerfstudio,
    instant-ngp); images are matched by name. refine_intrinsics: focal lengths and
    distortion refined by the manifest's bundle adjuster, poses held. Returns the summary
    `--json` prints (images_in_common, num_points3D, mean_reprojection_error, ...);
    InputError naming the file and image or field on bad input. Runs in a child process."""
    name = "triangulate"
    return typing.cast(Dict[str, Any], _call(
        _tessera.triangulate, output=_path(name, "output", output),
        model=_optional_path(name, "model", model), poses=_optional_path(name, "poses", poses),
        model_index=_int(name, "model_index", model_index, -2**31, 2**31 - 1),
        refine_intrinsics=_bool(name, "refine_intrinsics", refine_intrinsics),
        manifest=_manifest(name, manifest), threads=_int(name, "threads", threads)))


def register(output: PathLike, images: Optional[PathLike] = None, manifest: ManifestLike = None,
             model_index: int = 0, refine_existing: bool = False,
             camera_K: Optional[PathLike] = None, threads: int = 0,
             progress: Progress = None) -> Dict[str, Any]:
    """Registers the images of `images` (default: the workspace's folder) that are in no
    model into model `model_index` (sparse/N) by the incremental mapper's own
    registration step, holding the model's cameras, poses and points unless
    refine_existing (`tessera register`); returns the summary `--json` prints: each new
    image 'registered' or not with its 'reason'. camera_K: as the workspace was extracted
    with. Other arguments as run()'s."""
    name = "register"
    return typing.cast(Dict[str, Any], _call(
        _tessera.register, output=_path(name, "output", output),
        images=_optional_path(name, "images", images), manifest=_manifest(name, manifest),
        model_index=_int(name, "model_index", model_index, -2**31, 2**31 - 1),
        refine_existing=_bool(name, "refine_existing", refine_existing),
        camera_K=_optional_path(name, "camera_K", camera_K),
        threads=_int(name, "threads", threads), progress=_progress(name, progress)))


def adjust(model: PathLike, output: PathLike, manifest: ManifestLike = None,
           hold: Sequence[str] = ()) -> Dict[str, Any]:
    """Bundle-adjusts a COLMAP model with the manifest's bundle adjuster, then filters its
    points as the mappers do (`tessera adjust`), in a child process; hold: the blocks held
    constant ("intrinsics", "poses", "points"). Returns the summary: the mean reprojection
    error before and after, the points filtered."""
    name = "adjust"
    if isinstance(hold, str) or not all(isinstance(block, str) for block in hold):
        raise TypeError(f"adjust(): hold must be a list of str, not {_type_name(hold)}")
    return typing.cast(Dict[str, Any], _call(
        _tessera.adjust, model=_path(name, "model", model), output=_path(name, "output", output),
        manifest=_manifest(name, manifest), hold=list(hold)))


def align(model: PathLike, output: PathLike, reference: Optional[PathLike] = None,
          gps: bool = False, upright: bool = False, images: Optional[PathLike] = None,
          gps_sigma: Union[float, Sequence[float], None] = None) -> Dict[str, Any]:
    """Moves a COLMAP model by a similarity (`tessera align`), in a child process: onto the
    model `reference` (over the images both hold), onto its images' GPS (gps=True; images:
    their folder; gps_sigma: the tags' standard deviation in metres, horizontal or
    (horizontal, vertical)) or upright (upright=True). Writes the model and alignment.json into
    output; returns the summary (scale, rotation, translation, inliers, residuals)."""
    name = "align"
    for flag, value in (("gps", gps), ("upright", upright)):
        if not isinstance(value, bool):
            raise TypeError(f"align(): {flag} must be a bool, not {_type_name(value)}")
    sigma = None
    given: object = gps_sigma  # checked as what a caller may pass, not as it is typed
    if isinstance(given, numbers.Real) and not isinstance(given, bool):
        sigma = [float(given)]
    elif given is not None:
        if not isinstance(given, Sequence) or isinstance(given, str) or not all(
                isinstance(v, numbers.Real) and not isinstance(v, bool) for v in given):
            raise TypeError(f"align(): gps_sigma must be a number or a sequence of numbers, not "
                            f"{_type_name(given)}")
        sigma = [float(v) for v in given]
    return typing.cast(Dict[str, Any], _call(
        _tessera.align, model=_path(name, "model", model), output=_path(name, "output", output),
        reference=_optional_path(name, "reference", reference), gps=gps, upright=upright,
        images=_optional_path(name, "images", images), gps_sigma=sigma))


def plugins(manifest: ManifestLike = None) -> Dict[str, Any]:
    """The plugins found on the search path (manifest, a file or a dict: also its
    plugin_paths), as `tessera plugins --json` lists them, each usable one with its
    default 'options'."""
    return typing.cast(Dict[str, Any],
                       _call(_tessera.plugins, manifest=_manifest("plugins", manifest)))


def plugin_options(name: str, manifest: ManifestLike = None) -> Dict[str, Any]:
    """One plugin as `tessera plugins NAME --json` prints it: kind, name, version, file, and
    'options', a list of dicts (name, type, default, min and max for numbers, choices for
    strings, help), or None when the plugin does not describe its options. InputError
    when no plugin on the path (manifest: also its plugin_paths) has that name."""
    if not isinstance(name, str):
        raise TypeError(f"plugin_options(): name must be a str, not {_type_name(name)}")
    return typing.cast(Dict[str, Any], _call(
        _tessera.plugin_options, name=name, manifest=_manifest("plugin_options", manifest)))


def evaluate(model: PathLike, ground_truth: PathLike) -> Dict[str, Any]:
    """Scores a model folder's poses against ground truth (*.camera files, a
    transforms.json or a model folder) as `tessera eval --json` does; InputError when it
    cannot be aligned."""
    return typing.cast(Dict[str, Any], _call(
        _tessera.evaluate, model=_path("evaluate", "model", model),
        ground_truth=_path("evaluate", "ground_truth", ground_truth)))


def bench(images: PathLike, manifests: Sequence[PathLike], output: PathLike = "bench-output",
          ground_truth: Optional[PathLike] = None, camera_K: Optional[PathLike] = None,
          with_colmap: bool = False, colmap: Union[PathLike, Sequence[PathLike], None] = None,
          colmap_mapper_only: bool = False, threads: int = 0,
          child_timeout: float = 0) -> List[Dict[str, Any]]:
    """Runs each manifest file (each a `tessera run` of the installed executable, in
    OUTPUT/tessera/<name>) on the same images and returns the rows `tessera bench --json` writes,
    one dict per manifest (and COLMAP's): a row that failed keeps its exit_code.
    `colmap` names the COLMAP binary (or a list of them) to run instead of those
    with_colmap finds (`--colmap PATH`); colmap_mapper_only runs COLMAP's mappers alone on
    the first successful row's database (`--colmap-mapper-only`); each implies
    with_colmap. child_timeout: the seconds each row's process (a `tessera run`, each
    COLMAP step) may run before its row says it timed out (`--child-timeout`; 0: the
    default). A failing row keeps its exit_code and its error."""
    name = "bench"
    if colmap is None:
        colmaps: List[Any] = []
    elif isinstance(colmap, (str, os.PathLike)):
        colmaps = [colmap]
    else:
        colmaps = _paths(name, "colmap", colmap)
    return typing.cast(List[Dict[str, Any]], _call(
        _tessera.bench, images=_path(name, "images", images),
        manifests=_paths(name, "manifests", manifests), output=_path(name, "output", output),
        ground_truth=_optional_path(name, "ground_truth", ground_truth),
        camera_K=_optional_path(name, "camera_K", camera_K),
        with_colmap=_bool(name, "with_colmap", with_colmap), colmap=colmaps,
        colmap_mapper_only=_bool(name, "colmap_mapper_only", colmap_mapper_only),
        threads=_int(name, "threads", threads),
        child_timeout=_number(name, "child_timeout", child_timeout)))


# ---- pycolmap's names, where the meaning is the same ----

def _cam_from_world(image: Image) -> Rigid3d:
    return Rigid3d(image._cam_from_world_quat, image._cam_from_world_translation)


def _viewing_direction(image: Image) -> npt.NDArray[np.float64]:
    """The camera's optical axis (its +z) in the world, a unit (3,): the third row of R of
    cam_from_world, as pycolmap's."""
    return np.array(image.cam_from_world.rotation.matrix()[2])


def _reg_image_ids(self: Reconstruction) -> List[int]:
    """The ids of the registered images, ascending, as pycolmap's (a list of int)."""
    return [image_id for image_id, image in self.images.items() if image.registered]


def _compute_mean_track_length(self: Reconstruction) -> float:
    """COLMAP's mean track length: the observations of the registered images over the
    number of points; 0 for a model without points."""
    return float(self.statistics()["mean_track_length"])


def _transform(self: Reconstruction, sim3: Sim3d) -> None:
    """Moves the model by the similarity new_from_old, in place, as pycolmap's: every point
    x becomes sim3 * x and every pose cam_from_world becomes
    sim3.transform_camera_world(cam_from_world). Reprojection errors (in pixels) do not
    change."""
    if not isinstance(sim3, Sim3d):
        raise TypeError(f"transform(): sim3 must be a tessera.Sim3d, not {_type_name(sim3)}")
    self._transform(sim3.scale, sim3.rotation.matrix(), sim3.translation)


def _normalize(self: Reconstruction, fixed_scale: bool = False, extent: float = 10.0,
               min_percentile: float = 0.1, max_percentile: float = 0.9,
               use_images: bool = True) -> Sim3d:
    """Centres and scales the model in place, as pycolmap's (COLMAP 3.9 and later): over the
    registered images' projection centres (use_images) or the points, the coordinates
    between min_percentile and max_percentile of each axis give a box and a centroid; the
    model is moved so that the centroid is the origin and, unless fixed_scale, scaled so
    that the box's diagonal is `extent`. Returns the Sim3d applied (the identity, nothing
    moved, with fewer than 2 images or points)."""
    name = "normalize"
    fixed_scale = _bool(name, "fixed_scale", fixed_scale)
    use_images = _bool(name, "use_images", use_images)
    extent = _number(name, "extent", extent)
    low = _number(name, "min_percentile", min_percentile)
    high = _number(name, "max_percentile", max_percentile)
    if not (math.isfinite(extent) and extent > 0):
        raise InputError(f"extent: {extent} is not a positive finite number")
    if not 0 <= low <= high <= 1:
        raise InputError(f"min_percentile, max_percentile: {low}, {high} are not "
                         f"0 <= min_percentile <= max_percentile <= 1")
    if use_images:
        centres = [image.projection_center() for image in self.images.values()
                   if image.registered]
        coordinates = np.array(centres, dtype=np.float64).reshape(-1, 3)
    else:
        coordinates = self.points3D_arrays()["xyz"]
    if len(coordinates) < 2:
        return Sim3d()
    # COLMAP's ComputeBoundingBoxAndCentroid: per axis, the sorted values from
    # floor(low * (n - 1)) to ceil(high * (n - 1)).
    end = len(coordinates) - 1
    first = min(end, math.floor(low * end))
    last = min(end, math.ceil(high * end))
    kept = np.sort(coordinates, axis=0)[first:last + 1]
    centroid = kept.mean(axis=0)
    scale = 1.0
    if not fixed_scale:
        diagonal = float(np.linalg.norm(kept[-1] - kept[0]))
        if diagonal >= np.finfo(np.float64).eps:
            scale = extent / diagonal
    sim3 = Sim3d(scale, Rotation3d(), -scale * centroid)
    _transform(self, sim3)
    return sim3


def _compute_mean_reprojection_error(self: Reconstruction) -> float:
    """COLMAP's (and pycolmap's, and `colmap model_analyzer`'s) mean reprojection error:
    the mean of the points' stored errors (Point3D.error), over the points whose error is
    known (not -1); 0 when none is. Nothing is projected: after moving points or poses,
    compute_mean_reprojection_error_from_scratch() gives the current one."""
    errors = self.points3D_arrays()["errors"]
    known = errors[errors != -1]
    return float(known.mean()) if known.size else 0.0


def _compute_mean_reprojection_error_from_scratch(self: Reconstruction) -> float:
    """The mean reprojection error of the model as it is now: each point projected into
    the images of its track (those in front of their camera), the mean over points of each
    point's mean error; 0 for a model without points (statistics()'s
    mean_reprojection_error)."""
    value = float(self.statistics()["mean_reprojection_error"])
    return 0.0 if math.isnan(value) else value


def _find_image_with_name(self: Reconstruction, name: str) -> Optional[Image]:
    """The image of that name (relative to the image folder), None if there is none."""
    for image in self.images.values():
        if image.name == name:
            return image
    return None


def _num_points3D(self: Reconstruction) -> int:
    """How many 3D points the model has."""
    return len(self.points3D)


def _num_cameras(self: Reconstruction) -> int:
    """How many cameras the model has."""
    return len(self.cameras)


def _num_images(self: Reconstruction) -> int:
    """How many images the model has (registered or not)."""
    return len(self.images)


def _summary(self: Reconstruction) -> str:
    """A few lines of what the model holds, as pycolmap's summary()."""
    statistics = self.statistics()
    return "\n".join([
        "Reconstruction:",
        f"\tnum_cameras = {len(self.cameras)}",
        f"\tnum_images = {len(self.images)}",
        f"\tnum_reg_images = {self.num_reg_images()}",
        f"\tnum_points3D = {statistics['num_points3D']}",
        f"\tnum_observations = {statistics['num_observations']}",
        f"\tmean_track_length = {statistics['mean_track_length']:.6f}",
        f"\tmean_reprojection_error = {_compute_mean_reprojection_error(self):.6f}",
    ])


def _attach() -> None:
    # Set on the extension's classes: pycolmap's names beside the C++ ones.
    image_class: Any = Image
    image_class.cam_from_world = property(
        _cam_from_world, doc="x_cam = R @ x_world + t: a tessera.Rigid3d (a copy; pycolmap's "
                             "rotation.quat (x, y, z, w), translation, matrix(), inverse(), *)")
    image_class.viewing_direction = _viewing_direction
    model_class: Any = Reconstruction
    methods = (_compute_mean_reprojection_error, _compute_mean_reprojection_error_from_scratch,
               _compute_mean_track_length, _find_image_with_name, _normalize, _num_points3D,
               _num_cameras, _num_images, _reg_image_ids, _summary, _transform)
    for function in methods:
        setattr(model_class, function.__name__.lstrip("_"), function)
    for function in methods + (_viewing_direction,):
        function.__name__ = function.__qualname__ = function.__name__.lstrip("_")
        function.__module__ = __name__
    _model_edits.attach()
    _pycolmap_stages.attach()


_attach()
