"""pycolmap's pose classes over numpy: Rotation3d, Rigid3d (x_b = R x_a + t) and Sim3d
(x_b = s R x_a + t), with pycolmap's names and meanings.

They are immutable values: a rotation is held once, as a unit quaternion (x, y, z, w), and
its matrix is computed from it, so the two cannot disagree; a matrix given to a
constructor must be a rotation (InputError naming the argument otherwise). `*` composes
two of the same class or moves points ((3,) or (N, 3)); anything else is a TypeError, as
is `+`. Equality is within TOLERANCE (see __eq__)."""

import math
import numbers
from typing import Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

from ._tessera import InputError

F64 = npt.NDArray[np.float64]
# What `*` moves: one (3,) point or (N, 3) points. No scalar: `pose * 2` is a TypeError.
Points = Union[F64, Sequence[float], Sequence[Sequence[float]]]
RotationLike = Union["Rotation3d", F64, Sequence[float], Sequence[Sequence[float]]]

# Equality: rotation matrices within TOLERANCE per entry, translations within TOLERANCE
# times max(1, the larger norm) per entry, scales within TOLERANCE relative.
TOLERANCE = 1e-9
# A matrix is a rotation when |R^T R - I| (largest entry) and |det R - 1| are below this:
# a float32 file's matrix (about 1e-7) passes, a scaled or sheared one does not.
ROTATION_TOLERANCE = 1e-6
# A quaternion within this of unit length is normalised (as a pickled state's is).
UNIT_QUATERNION_TOLERANCE = 1e-3


def _type_name(value: object) -> str:
    return type(value).__name__


def _finite_array(function: str, name: str, value: object, shape: Tuple[int, ...]) -> F64:
    """`value` as a float64 array of `shape`: TypeError naming the argument for what is not
    numbers of that shape, InputError for a value that is not finite."""
    if value is None or isinstance(value, (str, bytes)):
        raise TypeError(f"{function}: {name} must be numbers of shape {shape}, not "
                        f"{_type_name(value)}")
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{function}: {name} must be numbers of shape {shape}, not "
                        f"{_type_name(value)}") from None
    if array.shape != shape:
        raise TypeError(f"{function}: {name} must have shape {shape}, not {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{function}: {name} holds a value that is not finite: "
                         f"{array.tolist()}")
    return array


def _shape(value: object) -> Tuple[int, ...]:
    """The shape of a list, tuple or array; () for anything else or a ragged list."""
    if not isinstance(value, (np.ndarray, list, tuple)):
        return ()
    try:
        return tuple(np.shape(value))
    except ValueError:
        return ()


def _readonly(array: F64) -> F64:
    array.flags.writeable = False
    return array


def _quat_from_matrix(matrix: F64) -> F64:
    """The unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method: the
    largest of the four squares first, for accuracy)."""
    m = matrix
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    squares = [trace, m[0, 0], m[1, 1], m[2, 2]]
    k = int(np.argmax(squares))
    if k == 0:
        s = math.sqrt(1 + trace) * 2
        quat = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s,
                s / 4]
    elif k == 1:
        s = math.sqrt(1 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        quat = [s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s,
                (m[2, 1] - m[1, 2]) / s]
    elif k == 2:
        s = math.sqrt(1 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        quat = [(m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s,
                (m[0, 2] - m[2, 0]) / s]
    else:
        s = math.sqrt(1 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        quat = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4,
                (m[1, 0] - m[0, 1]) / s]
    result = np.array(quat, dtype=np.float64)
    return np.asarray(result / np.linalg.norm(result), dtype=np.float64)


def _rotation_matrix(function: str, name: str, value: object) -> F64:
    matrix = _finite_array(function, name, value, (3, 3))
    orthogonality = float(np.max(np.abs(matrix.T @ matrix - np.eye(3))))
    determinant = float(np.linalg.det(matrix))
    if orthogonality > ROTATION_TOLERANCE or abs(determinant - 1) > ROTATION_TOLERANCE:
        raise InputError(f"{function}: {name} is not a rotation matrix (largest entry of "
                         f"R^T R - I: {orthogonality:.3g}, det R: {determinant:.6g})")
    return matrix


def _points(function: str, other: object) -> Optional[F64]:
    """`other` as (3,) or (N, 3) float64 points; None when it is not a list, tuple or array
    (so that `*` returns NotImplemented and Python raises its TypeError)."""
    if not isinstance(other, (np.ndarray, list, tuple)):
        return None
    try:
        points = np.array(other, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{function}: points must be numbers, a (3,) point or an (N, 3) "
                        f"array") from None
    if points.shape != (3,) and (points.ndim != 2 or points.shape[1] != 3):
        raise TypeError(f"{function}: points must be a (3,) point or an (N, 3) array, not "
                        f"shape {points.shape}")
    return points


class Rotation3d:
    """A rotation, pycolmap's Rotation3d: Rotation3d() is the identity; Rotation3d(quat)
    takes (x, y, z, w) (within 1e-3 of unit length, normalised); Rotation3d(matrix) a 3x3
    rotation matrix. quat, matrix(), inverse(), `*` another Rotation3d or points."""

    __slots__ = ("_quat",)
    __array_ufunc__ = None  # numpy defers to us: `array * rotation` is a TypeError

    def __init__(self, rotation: Union[F64, Sequence[float], Sequence[Sequence[float]],
                                       None] = None) -> None:
        function = "Rotation3d()"
        if rotation is None:
            self._quat = _readonly(np.array([0.0, 0.0, 0.0, 1.0]))
            return
        if _shape(rotation) == (3, 3):
            self._quat = _readonly(_quat_from_matrix(_rotation_matrix(function, "rotation",
                                                                      rotation)))
            return
        quat = _finite_array(function, "rotation (a quaternion (x, y, z, w) or a 3x3 matrix)",
                             rotation, (4,))
        norm = float(np.linalg.norm(quat))
        if abs(norm - 1) > UNIT_QUATERNION_TOLERANCE:
            raise InputError(f"{function}: the quaternion {quat.tolist()} has norm {norm:.6g}, "
                             f"not 1 (a rotation is a unit quaternion)")
        # Left as given when unit to rounding, so that a stored pose reads back bit for bit.
        self._quat = _readonly(quat if abs(norm - 1) <= 1e-15 else quat / norm)

    @property
    def quat(self) -> F64:
        """(x, y, z, w), unit length, read-only."""
        return self._quat

    def matrix(self) -> F64:
        """The 3x3 rotation matrix."""
        x, y, z, w = (float(value) for value in self._quat)
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])

    def inverse(self) -> "Rotation3d":
        x, y, z, w = self._quat
        return Rotation3d(np.array([-x, -y, -z, w]))

    def angle_to(self, other: "Rotation3d") -> float:
        """The angle in radians of the rotation between this one and `other`."""
        if not isinstance(other, Rotation3d):
            raise TypeError(f"Rotation3d.angle_to(): other must be a Rotation3d, not "
                            f"{_type_name(other)}")
        dot = min(1.0, abs(float(np.dot(self._quat, other._quat))))
        return 2 * math.acos(dot)

    @overload
    def __mul__(self, other: "Rotation3d") -> "Rotation3d": ...

    @overload
    def __mul__(self, other: Points) -> F64: ...

    def __mul__(self, other: object) -> object:
        if isinstance(other, Rotation3d):
            x1, y1, z1, w1 = self._quat
            x2, y2, z2, w2 = other._quat
            return Rotation3d(np.array([w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                                        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                                        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
                                        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2]))
        points = _points("Rotation3d * points", other)
        if points is None:
            return NotImplemented
        return np.asarray(points @ self.matrix().T, dtype=np.float64)

    def __eq__(self, other: object) -> bool:
        """The same rotation: matrices within TOLERANCE per entry (q and -q are equal)."""
        if not isinstance(other, Rotation3d):
            return NotImplemented
        return bool(np.max(np.abs(self.matrix() - other.matrix())) <= TOLERANCE)

    __hash__ = None  # type: ignore[assignment]  # equal within a tolerance: not hashable

    def __reduce__(self) -> Tuple[type, Tuple[Tuple[float, ...]]]:
        return (Rotation3d, (tuple(float(value) for value in self._quat),))

    def __repr__(self) -> str:
        return f"Rotation3d(quat_xyzw=[{', '.join(f'{v:.6g}' for v in self._quat)}])"


def _rotation(function: str, value: object) -> Rotation3d:
    if isinstance(value, Rotation3d):
        return value
    if isinstance(value, (np.ndarray, list, tuple)):
        try:
            return Rotation3d(value)
        except (TypeError, InputError) as error:
            message = str(error).replace("Rotation3d()", function, 1)
            raise type(error)(message) from None
    raise TypeError(f"{function}: rotation must be a Rotation3d, a quaternion (x, y, z, w) "
                    f"or a 3x3 matrix, not {_type_name(value)}")


def _translation_close(a: F64, b: F64) -> bool:
    scale = max(1.0, float(np.linalg.norm(a)), float(np.linalg.norm(b)))
    return bool(np.max(np.abs(a - b)) <= TOLERANCE * scale)


class Rigid3d:
    """A rigid transform b_from_a, x_b = R @ x_a + t (an image's cam_from_world), as
    pycolmap's: Rigid3d() is the identity; Rigid3d(rotation, translation) takes a
    Rotation3d, a quaternion (x, y, z, w) or a 3x3 rotation matrix, and a (3,)
    translation; Rigid3d(matrix) a 3x4 [R | t]. rotation, translation, matrix(),
    inverse(); `c_from_b * b_from_a` is c_from_a; `b_from_a * points` moves (3,) or
    (N, 3) points."""

    __slots__ = ("_rotation", "_translation")
    __array_ufunc__ = None  # numpy defers to us: `array * pose` is a TypeError

    def __init__(self, rotation: Union[RotationLike, None] = None,
                 translation: Union[F64, Sequence[float], None] = None) -> None:
        function = "Rigid3d()"
        if translation is None and _shape(rotation) == (3, 4):
            matrix = _finite_array(function, "matrix", rotation, (3, 4))
            self._rotation = _rotation(function, matrix[:, :3])
            self._translation = _readonly(np.array(matrix[:, 3]))
            return
        self._rotation = Rotation3d() if rotation is None else _rotation(function, rotation)
        self._translation = _readonly(np.zeros(3) if translation is None else _finite_array(
            function, "translation", translation, (3,)))

    @property
    def rotation(self) -> Rotation3d:
        return self._rotation

    @property
    def translation(self) -> F64:
        """(3,), read-only."""
        return self._translation

    def matrix(self) -> F64:
        """[R | t], 3x4."""
        return np.hstack([self._rotation.matrix(), self._translation.reshape(3, 1)])

    def inverse(self) -> "Rigid3d":
        """a_from_b of b_from_a: x_a = R^T x_b - R^T t."""
        inverse = self._rotation.inverse()
        return Rigid3d(inverse, -(inverse * self._translation))

    @overload
    def __mul__(self, other: "Rigid3d") -> "Rigid3d": ...

    @overload
    def __mul__(self, other: Points) -> F64: ...

    def __mul__(self, other: object) -> object:
        if isinstance(other, Rigid3d):
            return Rigid3d(self._rotation * other._rotation,
                           self._rotation * other._translation + self._translation)
        points = _points("Rigid3d * points", other)
        if points is None:
            return NotImplemented
        return np.asarray(self._rotation * points + self._translation, dtype=np.float64)

    def __eq__(self, other: object) -> bool:
        """The same transform: rotation matrices within TOLERANCE per entry and
        translations within TOLERANCE x max(1, |t|) per entry."""
        if not isinstance(other, Rigid3d):
            return NotImplemented
        return (self._rotation == other._rotation
                and _translation_close(self._translation, other._translation))

    __hash__ = None  # type: ignore[assignment]  # equal within a tolerance: not hashable

    def __reduce__(self) -> Tuple[type, Tuple[Rotation3d, Tuple[float, ...]]]:
        return (Rigid3d, (self._rotation, tuple(float(value) for value in self._translation)))

    def __repr__(self) -> str:
        return (f"Rigid3d(rotation_xyzw=[{', '.join(f'{v:.6g}' for v in self._rotation.quat)}], "
                f"translation=[{', '.join(f'{v:.6g}' for v in self._translation)}])")


class Sim3d:
    """A similarity b_from_a, x_b = scale * R @ x_a + t, as pycolmap's: Sim3d() is the
    identity; Sim3d(scale, rotation, translation), rotation as Rigid3d's; Sim3d(matrix) a
    3x4 [s R | t] (s > 0). scale, rotation, translation, matrix(), inverse(), `*` another
    Sim3d or points, transform_camera_world(cam_from_world)."""

    __slots__ = ("_scale", "_rotation", "_translation")
    __array_ufunc__ = None

    def __init__(self, scale: Union[float, F64, Sequence[Sequence[float]], None] = None,
                 rotation: Union[RotationLike, None] = None,
                 translation: Union[F64, Sequence[float], None] = None) -> None:
        function = "Sim3d()"
        if rotation is None and translation is None and _shape(scale) == (3, 4):
            matrix = _finite_array(function, "matrix", scale, (3, 4))
            determinant = float(np.linalg.det(matrix[:, :3]))
            if determinant <= 0:
                raise InputError(f"{function}: matrix's left 3x3 has determinant "
                                 f"{determinant:.6g}, not that of a positive scale times a "
                                 f"rotation")
            self._scale = float(np.cbrt(determinant))
            self._rotation = _rotation(function, matrix[:, :3] / self._scale)
            self._translation = _readonly(np.array(matrix[:, 3]))
            return
        if scale is None:
            self._scale = 1.0
        elif isinstance(scale, bool) or not isinstance(scale, numbers.Real):
            raise TypeError(f"{function}: scale must be a number (or the only argument a 3x4 "
                            f"matrix), not {_type_name(scale)}")
        elif not math.isfinite(float(scale)) or float(scale) <= 0:
            raise InputError(f"{function}: scale {float(scale)} is not a positive finite "
                             f"number")
        else:
            self._scale = float(scale)
        self._rotation = Rotation3d() if rotation is None else _rotation(function, rotation)
        self._translation = _readonly(np.zeros(3) if translation is None else _finite_array(
            function, "translation", translation, (3,)))

    @property
    def scale(self) -> float:
        return self._scale

    @property
    def rotation(self) -> Rotation3d:
        return self._rotation

    @property
    def translation(self) -> F64:
        """(3,), read-only."""
        return self._translation

    def matrix(self) -> F64:
        """[s R | t], 3x4."""
        return np.hstack([self._scale * self._rotation.matrix(),
                          self._translation.reshape(3, 1)])

    def inverse(self) -> "Sim3d":
        """a_from_b of b_from_a: x_a = R^T x_b / s - R^T t / s."""
        inverse = self._rotation.inverse()
        return Sim3d(1 / self._scale, inverse, -(inverse * self._translation) / self._scale)

    def transform_camera_world(self, cam_from_world: Rigid3d) -> Rigid3d:
        """cam_from_new_world of a camera whose cam_from_world was in the old world, self
        being new_from_old: the pose Reconstruction.transform(self) gives an image (the
        camera's frame keeps its scale)."""
        if not isinstance(cam_from_world, Rigid3d):
            raise TypeError(f"Sim3d.transform_camera_world(): cam_from_world must be a "
                            f"Rigid3d, not {_type_name(cam_from_world)}")
        rotation = cam_from_world.rotation * self._rotation.inverse()
        return Rigid3d(rotation, self._scale * cam_from_world.translation
                       - rotation * self._translation)

    @overload
    def __mul__(self, other: "Sim3d") -> "Sim3d": ...

    @overload
    def __mul__(self, other: Points) -> F64: ...

    def __mul__(self, other: object) -> object:
        if isinstance(other, Sim3d):
            return Sim3d(self._scale * other._scale, self._rotation * other._rotation,
                         self._scale * (self._rotation * other._translation)
                         + self._translation)
        points = _points("Sim3d * points", other)
        if points is None:
            return NotImplemented
        return np.asarray(self._scale * (self._rotation * points) + self._translation,
                          dtype=np.float64)

    def __eq__(self, other: object) -> bool:
        """The same similarity: scales within TOLERANCE relative, rotations and
        translations as Rigid3d's equality."""
        if not isinstance(other, Sim3d):
            return NotImplemented
        return (abs(self._scale - other._scale) <= TOLERANCE * max(self._scale, other._scale)
                and self._rotation == other._rotation
                and _translation_close(self._translation, other._translation))

    __hash__ = None  # type: ignore[assignment]  # equal within a tolerance: not hashable

    def __reduce__(self) -> Tuple[type, Tuple[float, Rotation3d, Tuple[float, ...]]]:
        return (Sim3d, (self._scale, self._rotation,
                        tuple(float(value) for value in self._translation)))

    def __repr__(self) -> str:
        return (f"Sim3d(scale={self._scale:.6g}, "
                f"rotation_xyzw=[{', '.join(f'{v:.6g}' for v in self._rotation.quat)}], "
                f"translation=[{', '.join(f'{v:.6g}' for v in self._translation)}])")
