"""pycolmap's pose classes (tessera.Rotation3d, Rigid3d, Sim3d), the getters beside them
(reg_image_ids, compute_mean_track_length, cam_from_img, viewing_direction,
focal_length) and Reconstruction.transform and normalize, on the sample's model and on
poses with known values."""

import copy
import math
import pickle

import numpy as np
import pytest

import tessera


def rotation_about(axis, angle):
    """A rotation matrix by Rodrigues' formula, independent of tessera's quaternions."""
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def homogeneous(matrix):
    return np.vstack([matrix, [0, 0, 0, 1]])


R1 = rotation_about([1, 2, 3], 0.7)
R2 = rotation_about([-2, 0.5, 1], 2.9)
T1 = np.array([0.5, -1.0, 2.0])
T2 = np.array([10.0, 3.0, -4.0])


@pytest.fixture
def model(sample):
    return tessera.Reconstruction(sample[2] / "sparse" / "0")


def test_rigid3d_composes_inverts_and_moves_points_as_4x4_matrices():
    a, b = tessera.Rigid3d(R1, T1), tessera.Rigid3d(R2, T2)
    np.testing.assert_allclose(a.matrix(), np.hstack([R1, T1[:, None]]), atol=1e-15)
    np.testing.assert_allclose(a.rotation.matrix(), R1, atol=1e-15)
    np.testing.assert_allclose((a * b).matrix(), (homogeneous(a.matrix()) @
                                                  homogeneous(b.matrix()))[:3], atol=1e-12)
    np.testing.assert_allclose(homogeneous(a.inverse().matrix()),
                               np.linalg.inv(homogeneous(a.matrix())), atol=1e-12)
    assert a * a.inverse() == tessera.Rigid3d() and a.inverse() * a == tessera.Rigid3d()
    points = np.array([[1.0, 2.0, 3.0], [-4.0, 0.0, 0.5]])
    np.testing.assert_allclose(a * points, points @ R1.T + T1, atol=1e-12)
    np.testing.assert_allclose(a * points[0], R1 @ points[0] + T1, atol=1e-12)
    assert (a * [1.0, 2.0, 3.0]).shape == (3,) and (a * np.zeros((0, 3))).shape == (0, 3)
    # From a 3x4 matrix, from the quaternion (x, y, z, w): the same pose.
    assert tessera.Rigid3d(a.matrix()) == a
    assert tessera.Rigid3d(tessera.Rotation3d(a.rotation.quat), T1) == a
    w = math.cos(0.35)
    quat = np.r_[math.sin(0.35) * np.array([1, 2, 3]) / np.linalg.norm([1, 2, 3]), w]
    np.testing.assert_allclose(a.rotation.quat, quat, atol=1e-15)
    assert repr(tessera.Rigid3d()) == "Rigid3d(rotation_xyzw=[0, 0, 0, 1], translation=[0, 0, 0])"


def test_sim3d_composes_inverts_and_moves_points_as_4x4_matrices():
    a, b = tessera.Sim3d(2.5, R1, T1), tessera.Sim3d(0.2, R2, T2)
    assert a.scale == 2.5
    np.testing.assert_allclose(a.matrix(), np.hstack([2.5 * R1, T1[:, None]]), atol=1e-15)
    np.testing.assert_allclose((a * b).matrix(), (homogeneous(a.matrix()) @
                                                  homogeneous(b.matrix()))[:3], atol=1e-12)
    np.testing.assert_allclose(homogeneous(a.inverse().matrix()),
                               np.linalg.inv(homogeneous(a.matrix())), atol=1e-12)
    assert a * a.inverse() == tessera.Sim3d()
    points = np.array([[1.0, 2.0, 3.0], [-4.0, 0.0, 0.5]])
    np.testing.assert_allclose(a * points, 2.5 * points @ R1.T + T1, atol=1e-12)
    back = tessera.Sim3d(a.matrix())
    assert back == a and back.scale == pytest.approx(2.5, rel=1e-14)
    # A camera moved with the world sees the same thing, scaled: s * (old pose * x).
    cam_from_world = tessera.Rigid3d(R2, T2)
    moved = a.transform_camera_world(cam_from_world)
    np.testing.assert_allclose(moved * (a * points), 2.5 * (cam_from_world * points), atol=1e-12)


def test_equality_is_within_the_documented_tolerance():
    a = tessera.Rigid3d(R1, T1)
    assert a == tessera.Rigid3d(R1, T1 + 1e-12)
    assert a != tessera.Rigid3d(R1, T1 + 1e-6)
    assert a != tessera.Rigid3d(rotation_about([1, 2, 3], 0.7 + 1e-6), T1)
    # q and -q are one rotation.
    assert tessera.Rotation3d(-a.rotation.quat) == a.rotation
    far = tessera.Rigid3d(R1, T1 * 1e6)
    assert far == tessera.Rigid3d(R1, T1 * 1e6 + 1e-4)  # relative to |t| beyond 1
    assert tessera.Rigid3d.__hash__ is None  # equal within a tolerance: not hashable
    assert tessera.Sim3d(2, R1, T1) != tessera.Sim3d(2 + 1e-6, R1, T1)
    assert (a == "pose") is False


def test_poses_pickle_and_copy_through_their_checking_constructor():
    for value in (tessera.Rigid3d(R1, T1), tessera.Sim3d(3.0, R2, T2), tessera.Rotation3d(R1)):
        for other in (pickle.loads(pickle.dumps(value)), copy.copy(value), copy.deepcopy(value)):
            assert type(other) is type(value) and other == value
            np.testing.assert_array_equal(other.matrix(), value.matrix())
    data = pickle.dumps(tessera.Rigid3d(R1, T1))
    assert b"tessera._geometry" in data and b"Rigid3d" in data
    # A tampered state goes through the constructor, which refuses it.
    with pytest.raises(tessera.InputError, match="norm"):
        tessera.Rotation3d.__reduce__(tessera.Rotation3d())[0]((2.0, 0.0, 0.0, 0.0))


def test_bad_poses_are_refused_naming_the_argument():
    with pytest.raises(tessera.InputError, match=r"Rigid3d\(\): rotation is not a rotation"):
        tessera.Rigid3d(2 * R1, T1)  # scaled
    with pytest.raises(tessera.InputError, match="not a rotation matrix"):
        tessera.Rigid3d(np.diag([1.0, 1.0, -1.0]), T1)  # a reflection
    with pytest.raises(tessera.InputError, match="not a rotation matrix"):
        tessera.Rigid3d(np.hstack([R1 + 1e-3, T1[:, None]]))
    with pytest.raises(tessera.InputError, match="translation holds a value that is not finite"):
        tessera.Rigid3d(R1, [0.0, math.nan, 0.0])
    with pytest.raises(tessera.InputError, match="not finite"):
        tessera.Rigid3d(np.where(np.eye(3) > 0, math.inf, 0.0), T1)
    with pytest.raises(tessera.InputError, match="norm 0"):
        tessera.Rotation3d([0.0, 0.0, 0.0, 0.0])
    with pytest.raises(TypeError, match="translation must have shape"):
        tessera.Rigid3d(R1, [1.0, 2.0])
    with pytest.raises(TypeError, match="rotation must be a Rotation3d"):
        tessera.Rigid3d("R", T1)
    with pytest.raises(TypeError, match="translation must be numbers"):
        tessera.Rigid3d(R1, "t")
    # The tuple's three arguments (matrix, translation, quaternion) are gone: a matrix and a
    # quaternion cannot both be given, so they cannot disagree.
    with pytest.raises(TypeError):
        tessera.Rigid3d(R1, T1, [0.0, 0.0, 0.0, 1.0])
    with pytest.raises(tessera.InputError, match="scale -1.0 is not a positive"):
        tessera.Sim3d(-1.0, R1, T1)
    with pytest.raises(TypeError, match="scale must be a number"):
        tessera.Sim3d("2", R1, T1)
    with pytest.raises(tessera.InputError, match="determinant"):
        tessera.Sim3d(np.hstack([-R1, T1[:, None]]))


def test_anything_but_a_pose_or_points_times_a_pose_is_a_type_error():
    pose, sim3 = tessera.Rigid3d(R1, T1), tessera.Sim3d(2.0, R1, T1)
    for value in (pose, sim3, pose.rotation):
        for other in (2, 2.0, "x", None, {1: 2}):
            with pytest.raises(TypeError):
                value * other
            with pytest.raises(TypeError):
                other * value
        with pytest.raises(TypeError):
            value + value
        with pytest.raises(TypeError):
            np.ones(3) * value  # numpy defers to the pose, which refuses
        with pytest.raises(TypeError, match=r"\(3,\) point or an \(N, 3\) array"):
            value * np.ones(2)
        with pytest.raises(TypeError):
            value()
    with pytest.raises(TypeError):
        pose * sim3
    with pytest.raises(TypeError):
        sim3 * pose
    with pytest.raises(AttributeError):
        pose.translation = T2
    with pytest.raises(ValueError, match="read-only"):
        pose.translation[0] = 1.0


def test_image_poses_are_rigid3d_from_the_stored_quaternion(model):
    for image in model.images.values():
        pose = image.cam_from_world
        assert isinstance(pose, tessera.Rigid3d)
        np.testing.assert_array_equal(pose.rotation.quat, image._cam_from_world_quat)
        R = pose.rotation.matrix()
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(pose.inverse().translation, image.projection_center(),
                                   atol=1e-9)
        np.testing.assert_allclose(image.viewing_direction(), R[2], atol=1e-15)
        assert np.linalg.norm(image.viewing_direction()) == pytest.approx(1, abs=1e-12)
        # pycolmap's own projection: img_from_cam(cam_from_world * xyz).
        point_ids = image.point3D_ids[image.point3D_ids != np.iinfo(np.uint64).max]
        if len(point_ids):
            xyz = np.array([model.points3D[int(i)].xyz for i in point_ids[:20]])
            camera = model.cameras[image.camera_id]
            np.testing.assert_allclose(camera.img_from_cam(pose * xyz),
                                       model.project(image.image_id, xyz), atol=1e-9)


def test_reg_image_ids_and_mean_track_length(model):
    ids = model.reg_image_ids()
    assert ids == sorted(i for i, image in model.images.items() if image.registered)
    assert all(type(i) is int for i in ids) and len(ids) == model.num_reg_images() > 0
    tracks = [len(point.track) for point in model.points3D.values()]
    assert model.compute_mean_track_length() == pytest.approx(np.mean(tracks), rel=1e-12)
    assert tessera.Reconstruction().compute_mean_track_length() == 0.0
    assert tessera.Reconstruction().reg_image_ids() == []


def test_cam_from_img_inverts_img_from_cam_with_distortion(model):
    camera = copy.deepcopy(model.cameras[next(iter(model.cameras))])
    assert camera.model == "SIMPLE_RADIAL"
    f, cx, cy, _ = camera.params
    camera.params = [f, cx, cy, -0.08]  # a distortion an undistortion must undo
    rng = np.random.default_rng(3)
    points = np.c_[rng.uniform(-0.4, 0.4, (50, 2)), rng.uniform(1, 5, 50)]
    pixels = camera.img_from_cam(points)
    # The distortion moves pixels far from the undistorted pinhole's.
    assert np.max(np.abs(pixels - (points[:, :2] / points[:, 2:] * f + [cx, cy]))) > 1
    np.testing.assert_allclose(camera.cam_from_img(pixels), points[:, :2] / points[:, 2:],
                               atol=1e-9)
    one = camera.cam_from_img(pixels[0])
    assert one.shape == (2,)
    np.testing.assert_allclose(one, points[0, :2] / points[0, 2], atol=1e-9)
    assert camera.cam_from_img(np.zeros((0, 2))).shape == (0, 2)
    with pytest.raises(TypeError, match=r"\(2,\) pixel or an \(N, 2\) array"):
        camera.cam_from_img(np.zeros((4, 3)))
    # What numpy cannot read as numbers: a TypeError naming the function and argument.
    for function in (camera.cam_from_img, camera.img_from_cam,
                     lambda points: model.project(1, points)):
        for bad, name in (("abc", "str"), (None, "NoneType"), ([[1.0, "a"]], "list")):
            with pytest.raises(TypeError, match=rf"\(\): points must be numbers, not {name}$"):
                function(bad)


def test_focal_lengths_as_pycolmap(model):
    camera = next(iter(model.cameras.values()))
    f = float(camera.params[0])
    assert camera.focal_length == camera.focal_length_x == camera.focal_length_y == f
    assert camera.mean_focal_length() == f
    pinhole = tessera._tessera._camera_from_state(
        (2, "PINHOLE", 640, 480, [500.0, 510.0, 320.0, 240.0]))
    assert (pinhole.focal_length_x, pinhole.focal_length_y) == (500.0, 510.0)
    assert pinhole.mean_focal_length() == 505.0
    with pytest.raises(tessera.InputError, match="PINHOLE has two focal lengths"):
        pinhole.focal_length


def test_transform_moves_every_pose_and_point_as_the_similarity_says(model):
    moved = copy.deepcopy(model)
    sim3 = tessera.Sim3d(3.7, R1, T2)
    error = model.compute_mean_reprojection_error_from_scratch()
    assert moved.transform(sim3) is None
    for image_id, image in model.images.items():
        assert moved.images[image_id].cam_from_world == sim3.transform_camera_world(
            image.cam_from_world)
        np.testing.assert_allclose(moved.images[image_id].projection_center(),
                                   sim3 * image.projection_center(), atol=1e-9)
    before, after = model.points3D_arrays(), moved.points3D_arrays()
    np.testing.assert_allclose(after["xyz"], sim3 * before["xyz"], atol=1e-9)
    np.testing.assert_array_equal(after["errors"], before["errors"])
    # A similarity moves nothing in the images: the reprojection errors stay.
    assert moved.compute_mean_reprojection_error_from_scratch() == pytest.approx(error,
                                                                                 rel=1e-9)
    moved.transform(sim3.inverse())
    for image_id, image in model.images.items():
        assert moved.images[image_id].cam_from_world == image.cam_from_world
    with pytest.raises(TypeError, match="transform\\(\\): sim3 must be a tessera.Sim3d"):
        moved.transform(tessera.Rigid3d())


def test_normalize_centres_and_scales_the_camera_centres(model):
    centres = np.array([model.images[i].projection_center() for i in model.reg_image_ids()])
    error = model.compute_mean_reprojection_error_from_scratch()
    # The whole range: the centroid is the centres' mean, the box their bounding box.
    moved = copy.deepcopy(model)
    sim3 = moved.normalize(extent=4.0, min_percentile=0.0, max_percentile=1.0)
    scale = 4.0 / np.linalg.norm(centres.max(axis=0) - centres.min(axis=0))
    assert sim3 == tessera.Sim3d(scale, tessera.Rotation3d(), -scale * centres.mean(axis=0))
    after = np.array([moved.images[i].projection_center() for i in moved.reg_image_ids()])
    np.testing.assert_allclose(after.mean(axis=0), 0, atol=1e-9)
    assert np.linalg.norm(after.max(axis=0) - after.min(axis=0)) == pytest.approx(4.0)
    for image_id, image in model.images.items():
        assert moved.images[image_id].cam_from_world == sim3.transform_camera_world(
            image.cam_from_world)
    assert moved.compute_mean_reprojection_error_from_scratch() == pytest.approx(error,
                                                                                 rel=1e-9)
    # pycolmap's defaults: percentiles 0.1..0.9 of each axis (COLMAP's floor and ceil of
    # p * (n - 1)), extent 10.
    moved = copy.deepcopy(model)
    sim3 = moved.normalize()
    n = len(centres)
    kept = np.sort(centres, axis=0)[math.floor(0.1 * (n - 1)):math.ceil(0.9 * (n - 1)) + 1]
    scale = 10.0 / np.linalg.norm(kept[-1] - kept[0])
    assert sim3 == tessera.Sim3d(scale, tessera.Rotation3d(), -scale * kept.mean(axis=0))
    fixed = copy.deepcopy(model).normalize(fixed_scale=True)
    assert fixed.scale == 1.0
    np.testing.assert_allclose(fixed.translation, -kept.mean(axis=0), atol=1e-12)
    # Over the points instead.
    xyz = model.points3D_arrays()["xyz"]
    sim3 = copy.deepcopy(model).normalize(use_images=False, min_percentile=0.0,
                                          max_percentile=1.0)
    np.testing.assert_allclose(sim3.translation, -sim3.scale * xyz.mean(axis=0), atol=1e-9)
    # Nothing to normalise: the identity.
    assert tessera.Reconstruction().normalize() == tessera.Sim3d()
    with pytest.raises(tessera.InputError, match="extent: -1.0 is not a positive"):
        model.normalize(extent=-1.0)
    with pytest.raises(tessera.InputError, match="min_percentile"):
        model.normalize(min_percentile=0.9, max_percentile=0.1)
    with pytest.raises(TypeError, match="normalize\\(\\): fixed_scale must be a bool"):
        model.normalize(fixed_scale=1)
