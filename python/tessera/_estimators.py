"""pycolmap's robust estimators on numpy over Tessera's own LO-RANSAC: estimate_absolute_pose,
estimate_essential_matrix, estimate_fundamental_matrix, estimate_homography_matrix and
estimate_two_view_geometry (the pipeline's geometric verification).

Options are dicts with pycolmap's keys: {"ransac": {"max_error": px, "confidence", ...}}
or the same RANSAC keys flat. A key that is not one of them is an InputError naming it.
Every run is deterministic: random_seed (default 0) seeds the sampling."""

import difflib
import numbers
from typing import Dict, Mapping, Optional, Tuple, TypedDict

import numpy as np
import numpy.typing as npt

from . import _tessera
from ._geometry import Rigid3d
from ._tessera import Camera, InputError

ArrayLike = npt.ArrayLike
Options = Optional[Mapping[str, object]]
_F64 = npt.NDArray[np.float64]
_Mask = npt.NDArray[np.bool_]


class AbsolutePoseResult(TypedDict):
    cam_from_world: Rigid3d
    num_inliers: int
    inlier_mask: _Mask


# The matrix estimators' results: the model under pycolmap's key, E, F or H.
EssentialMatrixResult = TypedDict("EssentialMatrixResult",
                                  {"E": _F64, "num_inliers": int, "inlier_mask": _Mask})
FundamentalMatrixResult = TypedDict("FundamentalMatrixResult",
                                    {"F": _F64, "num_inliers": int, "inlier_mask": _Mask})
HomographyMatrixResult = TypedDict("HomographyMatrixResult",
                                   {"H": _F64, "num_inliers": int, "inlier_mask": _Mask})


class TwoViewGeometryResult(TypedDict):
    """Database.two_view_geometry's fields, without the image ids."""
    config: int
    kind: Optional[str]  # "E", "F", "H" or None
    E: _F64
    F: _F64
    H: _F64
    cam2_from_cam1: Rigid3d
    inlier_matches: npt.NDArray[np.uint32]

# pycolmap's RANSACOptions fields. The defaults come from their owners in the host
# (_tessera._estimator_defaults: the pipeline's verification for the two-view matrices and
# geometry; the mapper's registration for the absolute pose's threshold and confidence);
# the absolute pose's inlier ratio and trial counts, and the seed, are this module's.
_FLOAT_KEYS = ("max_error", "min_inlier_ratio", "confidence", "dyn_num_trials_multiplier")
_INT_KEYS = ("min_num_trials", "max_num_trials", "random_seed")
_HOST_DEFAULTS = _tessera._estimator_defaults()
_ABSOLUTE_POSE_DEFAULTS: Dict[str, object] = {
    **_HOST_DEFAULTS["absolute_pose"], "min_inlier_ratio": 0.1, "min_num_trials": 100,
    "max_num_trials": 10000, "random_seed": 0}
_TWO_VIEW_DEFAULTS: Dict[str, object] = {**_HOST_DEFAULTS["two_view"], "random_seed": 0}
# The verification's RANSAC (no dyn_num_trials_multiplier: it uses the host's) and the
# keys of pycolmap's TwoViewGeometryOptions it honours, with the pipeline's defaults.
_TWO_VIEW_GEOMETRY_DEFAULTS: Dict[str, object] = {
    key: value for key, value in _TWO_VIEW_DEFAULTS.items()
    if key != "dyn_num_trials_multiplier"}
_TWO_VIEW_GEOMETRY_KEYS = ("min_num_inliers", "max_H_inlier_ratio")

# pycolmap's refinement keys Tessera's RefineAbsolutePose honours: it refines the pose only,
# so the focal length and extra parameters may be asked fixed (False), not refined.
_FIXED_REFINEMENT_KEYS = ("refine_focal_length", "refine_extra_params")


def _unknown(function: str, argument: str, key: object, valid: Tuple[str, ...]) -> InputError:
    close = difflib.get_close_matches(str(key), valid, n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return InputError(f"{function}: {argument} has no key {key!r}{hint}; valid keys: "
                      f"{', '.join(valid)}")


def _mapping(function: str, argument: str, value: object) -> Mapping[str, object]:
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise TypeError(f"{function}: {argument} must be a dict or None, not "
                        f"{type(value).__name__}")
    return value


def _ransac_value(function: str, key: str, value: object) -> object:
    """One RANSAC field checked for its type: TypeError naming the key."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{function}: ransac option {key} must be a number, not "
                        f"{type(value).__name__}")
    if key in _INT_KEYS:
        if not isinstance(value, numbers.Integral):
            raise TypeError(f"{function}: ransac option {key} must be a whole number, not "
                            f"{value!r}")
        if not 0 <= int(value) <= 2**31 - 1:
            raise InputError(f"{function}: ransac option {key} = {value} is not in 0..2^31-1")
        return int(value)
    if not np.isfinite(float(value)):
        raise InputError(f"{function}: ransac option {key} = {value} is not finite")
    return float(value)


def _ransac(function: str, argument: str, options: object,
            defaults: Mapping[str, object], extra_keys: Tuple[str, ...] = ()) -> Dict[str, object]:
    """The RANSAC fields of `options` ({"ransac": {...}} or flat), over `defaults`."""
    given = _mapping(function, argument, options)
    ransac = dict(defaults)
    ransac_keys = tuple(defaults)
    valid = ("ransac",) + ransac_keys + extra_keys
    nested = _mapping(function, f"{argument}['ransac']", given.get("ransac"))
    for key, value in nested.items():
        if key not in defaults:
            raise _unknown(function, f"{argument}['ransac']", key, ransac_keys)
        ransac[key] = _ransac_value(function, key, value)
    for key, value in given.items():
        if key == "ransac" or key in extra_keys:
            continue
        if key not in defaults:
            raise _unknown(function, argument, key, valid)
        if key in nested:
            raise InputError(f"{function}: {argument} gives {key} both flat and in 'ransac'")
        ransac[key] = _ransac_value(function, key, value)
    return ransac


def _camera(function: str, name: str, value: object) -> Camera:
    if not isinstance(value, Camera):
        raise TypeError(f"{function}: {name} must be a tessera.Camera, not "
                        f"{type(value).__name__}")
    return value


def estimate_absolute_pose(points2D: ArrayLike, points3D: ArrayLike, camera: Camera,
                           estimation_options: Options = None,
                           refinement_options: Options = None) -> Optional[AbsolutePoseResult]:
    """cam_from_world of a camera seeing points3D (N, 3) at pixels points2D (N, 2): P3P +
    EPnP LO-RANSAC on normalised points (threshold `max_error` pixels through the mean focal
    length), then refined on the inliers, as the mapper registers an image. Returns None
    when no pose has 3 inliers, else {"cam_from_world": Rigid3d, "num_inliers": int,
    "inlier_mask": (N,) bool}. estimation_options: pycolmap's {"ransac": {...}} (or flat),
    and "estimate_focal_length" False only; refinement_options: "refine" (default True),
    "refine_focal_length" and "refine_extra_params" False only."""
    function = "estimate_absolute_pose"
    _camera(function, "camera", camera)
    estimation = _mapping(function, "estimation_options", estimation_options)
    if estimation.get("estimate_focal_length", False) is not False:
        raise InputError(f"{function}: estimation_options estimate_focal_length: Tessera "
                         "estimates the pose with the camera's focal length (False only)")
    ransac = _ransac(function, "estimation_options", estimation, _ABSOLUTE_POSE_DEFAULTS,
                     ("estimate_focal_length",))
    refine = True
    for key, value in _mapping(function, "refinement_options", refinement_options).items():
        if key == "refine":
            if not isinstance(value, bool):
                raise TypeError(f"{function}: refinement_options refine must be a bool, not "
                                f"{type(value).__name__}")
            refine = value
        elif key in _FIXED_REFINEMENT_KEYS:
            if value is not False:
                raise InputError(f"{function}: refinement_options {key}: Tessera refines the "
                                 "pose only (False only)")
        else:
            raise _unknown(function, "refinement_options", key,
                           ("refine",) + _FIXED_REFINEMENT_KEYS)
    return _tessera._estimate_absolute_pose(points2D, points3D, camera, ransac, refine)


def estimate_essential_matrix(points1: ArrayLike, points2: ArrayLike, camera1: Camera,
                              camera2: Camera,
                              options: Options = None) -> Optional[EssentialMatrixResult]:
    """E (x2_cam^T E x1_cam = 0) of matching pixels points1, points2 (N, 2): five-point
    LO-RANSAC on normalised points, the threshold `max_error` pixels through each camera's
    mean focal length, averaged. None when no E has 5 inliers, else {"E": (3, 3),
    "num_inliers", "inlier_mask": (N,) bool}."""
    function = "estimate_essential_matrix"
    _camera(function, "camera1", camera1)
    _camera(function, "camera2", camera2)
    ransac = _ransac(function, "options", options, _TWO_VIEW_DEFAULTS)
    return _tessera._estimate_essential_matrix(points1, points2, camera1, camera2, ransac)


def estimate_fundamental_matrix(points1: ArrayLike, points2: ArrayLike,
                                options: Options = None) -> Optional[FundamentalMatrixResult]:
    """F (x2^T F x1 = 0 in pixels) of matching pixels points1, points2 (N >= 8, 2):
    seven-point LO-RANSAC with eight-point local fits, Sampson error below `max_error`
    pixels. None when no F has 7 inliers, else {"F": (3, 3), "num_inliers",
    "inlier_mask"}."""
    ransac = _ransac("estimate_fundamental_matrix", "options", options, _TWO_VIEW_DEFAULTS)
    return _tessera._estimate_fundamental_matrix(points1, points2, ransac)


def estimate_homography_matrix(points1: ArrayLike, points2: ArrayLike,
                               options: Options = None) -> Optional[HomographyMatrixResult]:
    """H (x2 ~ H x1 in pixels) of matching pixels points1, points2 (N >= 4, 2): four-point
    DLT LO-RANSAC, transfer error below `max_error` pixels. None when no H has 4 inliers,
    else {"H": (3, 3), "num_inliers", "inlier_mask"}."""
    ransac = _ransac("estimate_homography_matrix", "options", options, _TWO_VIEW_DEFAULTS)
    return _tessera._estimate_homography_matrix(points1, points2, ransac)


def estimate_two_view_geometry(camera1: Camera, points1: ArrayLike, camera2: Camera,
                               points2: ArrayLike, matches: Optional[ArrayLike] = None,
                               options: Options = None) -> TwoViewGeometryResult:
    """The pipeline's geometric verification of matches between pixels points1 (N1, 2) and
    points2 (N2, 2): `matches` (K, 2) indices, or row i to row i when None. E when both
    cameras have a prior focal length (cameras of a Database), else F; H flags planar or
    panoramic pairs; fewer than min_num_inliers inliers: config 1 (DEGENERATE), no
    inliers. Returns what Database.two_view_geometry does, without the image ids.
    options: pycolmap's {"ransac": {...}} (or flat; no dyn_num_trials_multiplier),
    "min_num_inliers" (default 15) and "max_H_inlier_ratio" (default 0.8)."""
    function = "estimate_two_view_geometry"
    _camera(function, "camera1", camera1)
    _camera(function, "camera2", camera2)
    given = _mapping(function, "options", options)
    settings = _ransac(function, "options", given, _TWO_VIEW_GEOMETRY_DEFAULTS,
                       _TWO_VIEW_GEOMETRY_KEYS)
    geometry_defaults = _HOST_DEFAULTS["two_view_geometry"]
    min_num_inliers = given.get("min_num_inliers", geometry_defaults["min_num_inliers"])
    if isinstance(min_num_inliers, bool) or not isinstance(min_num_inliers, numbers.Integral):
        raise TypeError(f"{function}: options min_num_inliers must be a whole number, not "
                        f"{min_num_inliers!r}")
    if not 0 <= int(min_num_inliers) <= 2**31 - 1:
        raise InputError(f"{function}: options min_num_inliers = {min_num_inliers} is not in "
                         "0..2^31-1")
    settings["min_num_inliers"] = int(min_num_inliers)
    settings["max_H_inlier_ratio"] = _ransac_value(
        function, "max_H_inlier_ratio",
        given.get("max_H_inlier_ratio", geometry_defaults["max_H_inlier_ratio"]))
    return _tessera._estimate_two_view_geometry(camera1, points1, camera2, points2, matches,
                                                settings)
