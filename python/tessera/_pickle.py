"""What a pickle of a Camera, Image, Point3D or Reconstruction calls to make the object
again (their __reduce__ names these): each passes the state to the extension's factory,
which checks every value (tessera.InputError, TypeError) and returns a whole object.

They are Python functions because pickle stores a function by its module and name, and
the extension's own functions (pybind11's) cannot be stored so."""

from typing import Any, Tuple

from . import _tessera


def camera_from_state(state: Tuple[Any, ...]) -> _tessera.Camera:
    return _tessera._camera_from_state(state)


def image_from_state(state: Tuple[Any, ...]) -> _tessera.Image:
    return _tessera._image_from_state(state)


def point3D_from_state(state: Tuple[Any, ...]) -> _tessera.Point3D:
    return _tessera._point3D_from_state(state)


def reconstruction_from_state(state: Tuple[Any, ...]) -> _tessera.Reconstruction:
    return _tessera._reconstruction_from_state(state)
