"""pycolmap's model building blocks on a tessera.Reconstruction: Point2D, TrackElement and
Track, an Image built in Python, the add_* and delete_* edits (checked in C++ against the
model, python/src/model_edit_bindings.cc), bundle_adjustment and triangulate_points through
the host's `adjust` and `triangulate` (each in a child process, with the manifest's bundle
adjuster), and align_reconstructions_via_proj_centers through `align --reference`'s step.

An edit never frees what Python holds: a Point3D object of a deleted point stays valid,
detached from the model. A point's track is a copy, (K, 2) uint32."""

import collections.abc
import logging
import numbers
import os
import shutil
import sqlite3
import tempfile
import typing
import urllib.parse
from typing import Any, Iterable, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _tessera
from ._geometry import Rigid3d, Rotation3d, Sim3d
from ._tessera import Camera, Image, InputError, Point3D, Reconstruction

# A manifest file, a bundled recipe's name, a dict, or None for default.json.
ManifestLike = Union[str, "os.PathLike[str]", Mapping[str, Any], None]
INVALID_ID = 2**32 - 1  # camera_t, image_t and point2D_t's "none"
INVALID_POINT3D_ID = 2**64 - 1


def _type_name(value: object) -> str:
    return type(value).__name__


def _id(function: str, name: str, value: object, high: int = INVALID_ID - 1) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{function}(): {name} must be an int, not {_type_name(value)}")
    if not 0 <= int(value) <= high:
        raise InputError(f"{function}: {name} {int(value)} is not in 0..{high}")
    return int(value)


class Point2D:
    """A keypoint of an image, as pycolmap's: xy in pixels and the id of the 3D point it
    observes (2**64-1 when none). Image.points2D gives copies: the model changes through
    Reconstruction.add_observation and delete_observation."""

    __slots__ = ("xy", "point3D_id")

    def __init__(self, xy: Union[npt.ArrayLike, None] = None,
                 point3D_id: int = INVALID_POINT3D_ID) -> None:
        self.xy = np.zeros(2) if xy is None else np.asarray(xy, dtype=np.float64).reshape(2)
        self.point3D_id = int(point3D_id)

    def has_point3D(self) -> bool:
        return self.point3D_id != INVALID_POINT3D_ID

    def __repr__(self) -> str:
        return f"Point2D(xy={self.xy.tolist()}, point3D_id={self.point3D_id})"


class TrackElement:
    """One observation of a 3D point: the image and the index of its keypoint."""

    __slots__ = ("image_id", "point2D_idx")

    def __init__(self, image_id: int = INVALID_ID, point2D_idx: int = INVALID_ID) -> None:
        self.image_id = _id("TrackElement", "image_id", image_id, INVALID_ID)
        self.point2D_idx = _id("TrackElement", "point2D_idx", point2D_idx, INVALID_ID)

    def __iter__(self) -> Iterator[int]:
        return iter((self.image_id, self.point2D_idx))

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, TrackElement) and self.image_id == other.image_id
                and self.point2D_idx == other.point2D_idx)

    def __repr__(self) -> str:
        return f"TrackElement(image_id={self.image_id}, point2D_idx={self.point2D_idx})"


TrackLike = Union["Track", Sequence[TrackElement], Sequence[Tuple[int, int]], npt.ArrayLike]


class Track:
    """The observations of a 3D point, as pycolmap's Track: elements, add_element,
    delete_element, length(). Reconstruction.add_point3D takes one (or a list of pairs, or a
    (K, 2) array); Point3D.track is a (K, 2) array (np.asarray(Track) gives the same)."""

    def __init__(self, elements: Iterable[Union[TrackElement, Tuple[int, int]]] = ()) -> None:
        self.elements: List[TrackElement] = []
        self.add_elements(elements)

    def add_element(self, image_id: int, point2D_idx: int) -> None:
        self.elements.append(TrackElement(image_id, point2D_idx))

    def add_elements(self, elements: Iterable[Union[TrackElement, Tuple[int, int]]]) -> None:
        for element in elements:
            image_id, point2D_idx = element
            self.add_element(image_id, point2D_idx)

    def delete_element(self, index: int) -> None:
        del self.elements[index]

    def length(self) -> int:
        return len(self.elements)

    def __len__(self) -> int:
        return len(self.elements)

    def __array__(self, dtype: Any = None) -> npt.NDArray[Any]:
        array = np.array([(e.image_id, e.point2D_idx) for e in self.elements],
                         dtype=np.uint32).reshape(-1, 2)
        return array if dtype is None else array.astype(dtype)

    def __repr__(self) -> str:
        return f"Track(length={len(self.elements)})"


def _track_pairs(function: str, track: object) -> List[Tuple[int, int]]:
    if isinstance(track, Track):
        return [(e.image_id, e.point2D_idx) for e in track.elements]
    if isinstance(track, (str, bytes)) or track is None:
        raise TypeError(f"{function}(): track must be a Track, a list of (image_id, "
                        f"point2D_idx) or a (K, 2) array, not {_type_name(track)}")
    pairs = []
    try:
        rows = list(track)  # type: ignore[call-overload]
    except TypeError:
        raise TypeError(f"{function}(): track must be a Track, a list of (image_id, "
                        f"point2D_idx) or a (K, 2) array, not {_type_name(track)}") from None
    for index, row in enumerate(rows):
        if isinstance(row, TrackElement):
            pairs.append((row.image_id, row.point2D_idx))
            continue
        items = list(row) if isinstance(row, (Sequence, np.ndarray)) else []
        if len(items) != 2:
            raise TypeError(f"{function}(): track[{index}] must be (image_id, point2D_idx), "
                            f"not {row!r}")
        pairs.append((_id(function, f"track[{index}] image_id", items[0]),
                      _id(function, f"track[{index}] point2D_idx", items[1])))
    return pairs


# ---- Image, built in Python ----

_image_init: Any = Image.__init__  # the C++ constructor, before attach() replaces it


def _image_new(self: Image, name: str = "", points2D: Union[npt.ArrayLike, Sequence[Point2D],
                                                              None] = None,
               cam_from_world: Optional[Rigid3d] = None, camera_id: int = INVALID_ID,
               image_id: int = INVALID_ID) -> None:
    """An image for Reconstruction.add_image, as pycolmap's constructor: its name (relative
    to the image folder), keypoints (an (N, 2) array of pixels or a list of Point2D, their
    3D points left out), pose (default: the identity) and ids. Unregistered until
    Reconstruction.register_image. InputError naming what does not fit."""
    if not isinstance(name, str):
        raise TypeError(f"Image(): name must be a str, not {_type_name(name)}")
    if cam_from_world is None:
        cam_from_world = Rigid3d()
    if not isinstance(cam_from_world, Rigid3d):
        raise TypeError(f"Image(): cam_from_world must be a tessera.Rigid3d, not "
                        f"{_type_name(cam_from_world)}")
    rows: List[List[float]] = []
    if points2D is not None:
        given: Any = points2D
        if isinstance(given, (list, tuple)) and given and isinstance(given[0], Point2D):
            rows = [list(point.xy) for point in given]
        else:
            array = np.asarray(given, dtype=np.float64)
            if array.size == 0:
                array = array.reshape(0, 2)
            if array.ndim != 2 or array.shape[1] != 2:
                raise TypeError(f"Image(): points2D must be an (N, 2) array of pixels or a list "
                                f"of Point2D, not shape {array.shape}")
            rows = array.tolist()
    _image_init(self, name, rows, tuple(float(v) for v in cam_from_world.rotation.quat),
                tuple(float(v) for v in cam_from_world.translation),
                _id("Image", "camera_id", camera_id, INVALID_ID),
                _id("Image", "image_id", image_id, INVALID_ID))


def _points2D(image: Image) -> List[Point2D]:
    """The keypoints as pycolmap's list of Point2D (xy, point3D_id, has_point3D()): copies."""
    return [Point2D(xy, int(point3D_id))
            for xy, point3D_id in zip(image.keypoints, image.point3D_ids)]


# ---- The edits ----

def _add_camera(self: Reconstruction, camera: Camera) -> int:
    """Adds a copy of the camera under its camera_id; returns the id. InputError when the
    model has a camera of that id."""
    if not isinstance(camera, Camera):
        raise TypeError(f"add_camera(): camera must be a tessera.Camera, not {_type_name(camera)}")
    return int(self._add_camera(camera))


def _add_image(self: Reconstruction, image: Image) -> int:
    """Adds a copy of the image (registered as it is; its keypoints observe no point yet);
    returns its id. InputError for an id or name the model has, or a camera it lacks."""
    if not isinstance(image, Image):
        raise TypeError(f"add_image(): image must be a tessera.Image, not {_type_name(image)}")
    return int(self._add_image(image))


def _register_image(self: Reconstruction, image_id: int) -> None:
    """Marks the image registered: its pose counts, write() saves it."""
    self._register_image(_id("register_image", "image_id", image_id))


def _deregister_image(self: Reconstruction, image_id: int) -> None:
    """Removes the image's observations (points left with fewer than two go too, as
    COLMAP's) and marks it not registered."""
    self._deregister_image(_id("deregister_image", "image_id", image_id))


def _add_point3D(self: Reconstruction, xyz: npt.ArrayLike, track: TrackLike,
                 color: npt.ArrayLike = (0, 0, 0)) -> int:
    """Adds a point at xyz (world frame) observed by the track's keypoints, each of a
    registered image and with no point yet; returns its id (above every id the model had).
    Its error is unknown (-1) until the model is adjusted."""
    name = "add_point3D"
    position = np.asarray(xyz, dtype=np.float64)
    if position.shape != (3,):
        raise TypeError(f"{name}(): xyz must have shape (3,), not {position.shape}")
    rgb = np.asarray(color)
    if rgb.shape != (3,) or not np.issubdtype(rgb.dtype, np.integer) or rgb.min() < 0 or \
            rgb.max() > 255:
        raise TypeError(f"{name}(): color must be 3 ints in 0..255, not {np.asarray(color)!r}")
    return int(self._add_point3D(position.tolist(), _track_pairs(name, track),
                                 [int(v) for v in rgb]))


def _add_observation(self: Reconstruction, point3D_id: int,
                     track_element: Union[TrackElement, Tuple[int, int]]) -> None:
    """Adds the keypoint (image_id, point2D_idx) to the point's track."""
    name = "add_observation"
    pairs = _track_pairs(name, [track_element])
    self._add_observation(_id(name, "point3D_id", point3D_id, INVALID_POINT3D_ID - 1),
                          *pairs[0])


def _delete_observation(self: Reconstruction, image_id: int, point2D_idx: int) -> None:
    """Removes the keypoint's observation from its point; the point goes too when it would
    keep fewer than two (COLMAP's)."""
    name = "delete_observation"
    self._delete_observation(_id(name, "image_id", image_id),
                             _id(name, "point2D_idx", point2D_idx))


def _delete_point3D(self: Reconstruction, point3D_id: int) -> None:
    """Removes the point and every keypoint's reference to it."""
    self._delete_point3D(_id("delete_point3D", "point3D_id", point3D_id, INVALID_POINT3D_ID - 1))


def _exists_point3D(self: Reconstruction, point3D_id: int) -> bool:
    return point3D_id in self.points3D


def _exists_image(self: Reconstruction, image_id: int) -> bool:
    return image_id in self.images


def _exists_camera(self: Reconstruction, camera_id: int) -> bool:
    return camera_id in self.cameras


# ---- Whole-model steps ----

def _work_folder(prefix: str) -> str:
    """A new folder of this process and thread alone."""
    return tempfile.mkdtemp(prefix=f"tessera-{prefix}-")


def bundle_adjustment(reconstruction: Reconstruction, options: Optional[Mapping[str, Any]] = None,
                      manifest: ManifestLike = None, hold: Sequence[str] = ()) -> Mapping[str, Any]:
    """Bundle-adjusts the model in place with the manifest's bundle adjuster (pycolmap's
    bundle_adjustment), then filters its points as the mappers do: tessera.adjust on a
    copy, whose result replaces the model's cameras, poses and points (the objects Python
    holds see the new values). options: pycolmap's BundleAdjustmentOptions are not read;
    pass None. hold: blocks held constant ("intrinsics", "poses", "points"). Returns
    adjust()'s summary."""
    from . import adjust  # the layer that checks the arguments

    if not isinstance(reconstruction, Reconstruction):
        raise TypeError(f"bundle_adjustment(): reconstruction must be a tessera.Reconstruction, "
                        f"not {_type_name(reconstruction)}")
    if options is not None:
        raise InputError("bundle_adjustment: options: Tessera's adjustment is set by the "
                         "manifest's bundle_adjuster and mapper options; pass manifest=")
    folder = _work_folder("bundle-adjustment")
    try:
        reconstruction.write(os.path.join(folder, "in"))
        summary = adjust(os.path.join(folder, "in"), os.path.join(folder, "out"),
                         manifest=manifest, hold=hold)
        reconstruction._update_from(Reconstruction(os.path.join(folder, "out")))
        return summary
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def triangulate_points(reconstruction: Reconstruction, database_path: Union[str, "os.PathLike[str]"],
                       image_path: Union[str, "os.PathLike[str]"], output_path: Union[str, "os.PathLike[str]"],
                       clear_points: bool = True, options: Optional[Mapping[str, Any]] = None,
                       refine_intrinsics: bool = False, manifest: ManifestLike = None) -> Reconstruction:
    """Triangulates the workspace's verified matches for the model's registered images,
    every pose held (pycolmap's triangulate_points, COLMAP's point_triangulator), through
    tessera.triangulate. database_path is a workspace's database.db; the new points replace
    the model's (in place, returned) and the model is written to output_path (COLMAP
    binary). clear_points=False (keeping the old points) is not supported: Tessera
    triangulates every track afresh. image_path must be a folder (the workspace records
    its images)."""
    from . import triangulate

    name = "triangulate_points"
    if not isinstance(reconstruction, Reconstruction):
        raise TypeError(f"{name}(): reconstruction must be a tessera.Reconstruction, not "
                        f"{_type_name(reconstruction)}")
    if clear_points is not True:
        raise InputError(f"{name}: clear_points=False: Tessera triangulates every track "
                         f"afresh, replacing the model's points")
    if options is not None:
        raise InputError(f"{name}: options: Tessera's thresholds are the mapper's; pass "
                         f"manifest=")
    workspace_of(name, database_path)
    if not os.path.isdir(image_path):
        raise InputError(f"{name}: image_path: {os.fspath(image_path)}: no such folder")
    output_folder(name, output_path)
    folder = _work_folder("triangulate")
    try:
        reconstruction.write(os.path.join(folder, "in"))
        # A scratch workspace with a copy of the database (SQLite's backup, consistent while
        # another process reads it): nothing is written into the caller's workspace.
        scratch = os.path.join(folder, "workspace")
        os.mkdir(scratch)
        _copy_database(os.fspath(database_path), os.path.join(scratch, _tessera._DATABASE_FILE))
        triangulate(scratch, model=os.path.join(folder, "in"),
                    refine_intrinsics=refine_intrinsics, manifest=manifest)
        triangulated = Reconstruction(os.path.join(scratch, _tessera._MODELS_FOLDER, "0"))
        reconstruction._update_from(_with_ids_of(reconstruction, triangulated, name))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(output_path, exist_ok=True)
    reconstruction.write(output_path)
    return reconstruction


def _with_ids_of(model: Reconstruction, result: Reconstruction,
                 function: str) -> Reconstruction:
    """`result` (triangulate's model: the workspace's image ids and keypoints) with the
    image ids of `model`'s images of the same names. InputError where an image's keypoints
    are not the workspace's: the points would observe keypoints the model does not have."""
    own = {image.name: image for image in model.images.values()}
    cameras, images, points = result.__getstate__()
    image_ids = {}
    renamed = []
    for image_state in images:
        image_id, camera_id, name, registered, quat, translation, points2D = image_state
        mine = own[name]
        keypoints = np.array([point[:2] for point in points2D], dtype=np.float64).reshape(-1, 2)
        if keypoints.shape != mine.keypoints.shape or not np.allclose(keypoints, mine.keypoints,
                                                                      atol=1e-6):
            raise InputError(
                f"{function}: image {mine.image_id} ({name}) has {len(mine.keypoints)} "
                f"keypoints that are not the workspace's {len(keypoints)}: the model must be "
                f"made from this workspace (tessera.triangulate takes a model from elsewhere "
                f"and writes a new one)")
        image_ids[image_id] = mine.image_id
        renamed.append((mine.image_id, camera_id, name, registered, quat, translation,
                        points2D))
    moved_points = [(point3D_id, (xyz, color, error,
                                  [(image_ids[image_id], idx) for image_id, idx in track]))
                    for point3D_id, (xyz, color, error, track) in points]
    return _tessera._reconstruction_from_state((cameras, renamed, moved_points))


def _copy_database(source: str, target: str) -> None:
    if not os.path.isfile(source):
        raise InputError(f"{source}: no such database")
    with sqlite3.connect(f"file:{urllib.parse.quote(source)}?mode=ro", uri=True) as reader, \
            sqlite3.connect(target) as writer:
        reader.backup(writer)


def output_folder(function: str, output_path: Union[str, "os.PathLike[str]"]) -> str:
    """output_path as a folder to write into, checked before any work: InputError naming it
    when it is a file (or lies under one)."""
    if not isinstance(output_path, (str, os.PathLike)):
        raise TypeError(f"{function}(): output_path must be a path, not {_type_name(output_path)}")
    path = os.fspath(output_path)
    probe = path
    while probe and not os.path.exists(probe):
        probe = os.path.dirname(probe)
    if probe and not os.path.isdir(probe):
        raise InputError(f"{function}: output_path: {path}: {probe} is a file, not a folder")
    return path


def workspace_of(function: str, database_path: Union[str, "os.PathLike[str]"]) -> str:
    """The workspace folder of a pycolmap database_path: Tessera keeps its database as
    WORKSPACE/database.db."""
    if not isinstance(database_path, (str, os.PathLike)):
        raise TypeError(f"{function}(): database_path must be a path, not "
                        f"{_type_name(database_path)}")
    path = os.fspath(database_path)
    name = _tessera._DATABASE_FILE
    if os.path.basename(path) != name:
        raise InputError(f"{function}: database_path: {path}: Tessera keeps its database as "
                         f"{name} in a workspace folder; name it WORKSPACE/{name}")
    return os.path.dirname(os.path.abspath(path))


def align_reconstructions_via_proj_centers(src_reconstruction: Reconstruction,
                                           tgt_reconstruction: Reconstruction,
                                           max_proj_center_error: float) -> Optional[Sim3d]:
    """tgt_from_src, as pycolmap's: LO-RANSAC on the camera centres of the registered images
    both models hold by name (inliers within max_proj_center_error, in the target's
    units), refitted on the inliers; the model is not moved (Reconstruction.transform does
    that). None when there is none (fewer than 3 shared images, centres on a line, no
    consensus); the reason is logged on logger "tessera"."""
    for name, value in (("src_reconstruction", src_reconstruction),
                        ("tgt_reconstruction", tgt_reconstruction)):
        if not isinstance(value, Reconstruction):
            raise TypeError(f"align_reconstructions_via_proj_centers(): {name} must be a "
                            f"tessera.Reconstruction, not {_type_name(value)}")
    if isinstance(max_proj_center_error, bool) or not isinstance(max_proj_center_error,
                                                                 numbers.Real):
        raise TypeError(f"align_reconstructions_via_proj_centers(): max_proj_center_error must "
                        f"be a number, not {_type_name(max_proj_center_error)}")
    if not float(max_proj_center_error) > 0:
        raise InputError(f"max_proj_center_error: {max_proj_center_error} is not positive")
    try:
        fit = _tessera._align_to_reference(src_reconstruction, tgt_reconstruction,
                                           float(max_proj_center_error))
    except InputError as error:
        logging.getLogger("tessera").warning("align_reconstructions_via_proj_centers: %s", error)
        return None
    return Sim3d(fit["scale"], Rotation3d(fit["rotation"]), fit["translation"])


def _safe_iteration(map_class: Any) -> None:
    """The id maps iterate over a snapshot of their ids, skipping those deleted meanwhile:
    `for point3D_id, point in rec.points3D.items(): rec.delete_point3D(...)` visits every
    point that is still there once (pybind11's own iterators walk the C++ map, which an
    edit changes under them). Ids added during the loop are not visited."""
    walk = map_class.__iter__  # pybind11's, over the C++ map: run through at once

    def iterate(self: Any) -> Iterator[Any]:
        for key in list(walk(self)):
            if key in self:
                yield key

    map_class.__iter__ = iterate
    map_class.keys = lambda self: collections.abc.KeysView(self)
    map_class.values = lambda self: collections.abc.ValuesView(self)
    map_class.items = lambda self: collections.abc.ItemsView(self)


def attach() -> None:
    for value_class in (Camera, Image, Point3D):
        _safe_iteration(typing.cast(Any, value_class).Map)
    image_class: Any = Image
    image_class.__init__ = _image_new
    image_class.points2D = property(_points2D, doc=_points2D.__doc__)
    model_class: Any = Reconstruction
    for function in (_add_camera, _add_image, _register_image, _deregister_image, _add_point3D,
                     _add_observation, _delete_observation, _delete_point3D, _exists_point3D,
                     _exists_image, _exists_camera):
        public = function.__name__.lstrip("_")
        function.__name__ = function.__qualname__ = public
        setattr(model_class, public, function)
    _image_new.__name__ = _image_new.__qualname__ = "__init__"
