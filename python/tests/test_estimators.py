"""tessera.estimate_absolute_pose, estimate_essential_matrix, estimate_fundamental_matrix and
estimate_homography_matrix on synthetic scenes with known truth, pixel noise and 30%
outliers: the model against the truth, the inlier mask against the outliers, determinism,
and the refusals of bad input."""

import numpy as np
import pytest

import tessera

CAMERA_ARGS = ("SIMPLE_PINHOLE", 640, 480, [500.0, 320.0, 240.0])
NOISE_PX = 0.5
OUTLIER_RATIO = 0.3


def camera():
    return tessera.Camera(*CAMERA_ARGS)


def unit(quat):
    quat = np.asarray(quat, dtype=float)
    return quat / np.linalg.norm(quat)


def rotation_angle_deg(r1, r2):
    cos = (np.trace(r1.T @ r2) - 1) / 2
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def epipolar_distance_px(F, x1, x2):
    """Distance of each x2 from the epipolar line F x1, in pixels of image 2."""
    h1 = np.c_[x1, np.ones(len(x1))]
    h2 = np.c_[x2, np.ones(len(x2))]
    lines = h1 @ F.T
    return np.abs(np.sum(lines * h2, axis=1)) / np.linalg.norm(lines[:, :2], axis=1)


def far_from_line(rng, F, x1, minimum=50.0):
    """A random pixel of image 2 at least `minimum` px off the epipolar line of x1."""
    while True:
        candidate = rng.uniform([0, 0], [640, 480], (1, 2))
        if epipolar_distance_px(F, x1[None], candidate)[0] > minimum:
            return candidate[0]


@pytest.fixture(scope="module")
def pose_scene():
    rng = np.random.default_rng(7)
    cam = camera()
    cam_from_world = tessera.Rigid3d(unit([0.1, -0.2, 0.05, 1.0]), [0.4, -0.3, 1.0])
    # Points in front of the camera and inside the image.
    points_cam = np.c_[rng.uniform(-0.5, 0.5, (200, 2)), np.ones(200)] * rng.uniform(
        4, 9, (200, 1))
    points3D = cam_from_world.inverse() * points_cam
    pixels = cam.img_from_cam(points_cam) + rng.normal(0, NOISE_PX, (200, 2))
    outlier = rng.random(200) < OUTLIER_RATIO
    # Outliers at least 50 px from where the point projects.
    offsets = rng.uniform(50, 150, outlier.sum())[:, None] * np.c_[
        np.cos(angles := rng.uniform(0, 2 * np.pi, outlier.sum())), np.sin(angles)]
    pixels[outlier] += offsets
    return cam, cam_from_world, points3D, pixels, outlier


def test_absolute_pose_recovers_the_pose_and_flags_the_outliers(pose_scene):
    cam, truth, points3D, pixels, outlier = pose_scene
    result = tessera.estimate_absolute_pose(pixels, points3D, cam)
    assert result is not None
    pose = result["cam_from_world"]
    assert isinstance(pose, tessera.Rigid3d)
    assert rotation_angle_deg(pose.rotation.matrix(), truth.rotation.matrix()) < 0.05
    assert np.linalg.norm(pose.translation - truth.translation) < 0.01
    mask = result["inlier_mask"]
    assert mask.dtype == np.bool_ and mask.shape == (len(pixels),)
    np.testing.assert_array_equal(mask, ~outlier)
    assert result["num_inliers"] == int((~outlier).sum())


def test_absolute_pose_is_deterministic_and_takes_pycolmaps_options(pose_scene):
    cam, truth, points3D, pixels, _ = pose_scene
    first = tessera.estimate_absolute_pose(pixels, points3D, cam)
    again = tessera.estimate_absolute_pose(pixels, points3D, cam)
    assert first is not None and again is not None
    np.testing.assert_array_equal(first["cam_from_world"].matrix(), again["cam_from_world"].matrix())
    np.testing.assert_array_equal(first["inlier_mask"], again["inlier_mask"])
    nested = tessera.estimate_absolute_pose(
        pixels, points3D, cam, {"ransac": {"max_error": 8.0, "confidence": 0.999,
                                           "min_num_trials": 50, "max_num_trials": 5000,
                                           "min_inlier_ratio": 0.2, "random_seed": 3}})
    flat = tessera.estimate_absolute_pose(
        pixels, points3D, cam, {"max_error": 8.0, "confidence": 0.999, "min_num_trials": 50,
                                "max_num_trials": 5000, "min_inlier_ratio": 0.2,
                                "random_seed": 3})
    assert nested is not None and flat is not None
    np.testing.assert_array_equal(nested["cam_from_world"].matrix(), flat["cam_from_world"].matrix())
    assert rotation_angle_deg(nested["cam_from_world"].rotation.matrix(),
                              truth.rotation.matrix()) < 0.05
    # Without refinement, the LO-RANSAC pose: close, and not the refined one.
    raw = tessera.estimate_absolute_pose(pixels, points3D, cam, None, {"refine": False})
    assert raw is not None
    assert rotation_angle_deg(raw["cam_from_world"].rotation.matrix(),
                              truth.rotation.matrix()) < 0.5
    # A threshold below the noise keeps fewer inliers.
    tight = tessera.estimate_absolute_pose(pixels, points3D, cam, {"ransac": {"max_error": 0.3}})
    assert tight is not None and tight["num_inliers"] < first["num_inliers"]


@pytest.fixture(scope="module")
def two_view_scene():
    rng = np.random.default_rng(11)
    cam = camera()
    K = np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]])
    cam2_from_cam1 = tessera.Rigid3d(unit([0.02, 0.1, -0.03, 1.0]), [-1.0, 0.1, 0.2])
    points_cam1 = np.c_[rng.uniform(-0.4, 0.4, (200, 2)), np.ones(200)] * rng.uniform(
        5, 10, (200, 1))
    x1 = cam.img_from_cam(points_cam1) + rng.normal(0, NOISE_PX, (200, 2))
    x2 = cam.img_from_cam(cam2_from_cam1 * points_cam1) + rng.normal(0, NOISE_PX, (200, 2))
    R, t = cam2_from_cam1.rotation.matrix(), cam2_from_cam1.translation
    E_true = skew(t) @ R
    F_true = np.linalg.inv(K).T @ E_true @ np.linalg.inv(K)
    outlier = rng.random(200) < OUTLIER_RATIO
    # Outliers in image 2 at least 50 px off their true epipolar line.
    for i in np.flatnonzero(outlier):
        x2[i] = far_from_line(rng, F_true, x1[i])
    return cam, E_true, F_true, x1, x2, outlier


def normalized_up_to_sign(M, reference):
    M = M / np.linalg.norm(M)
    reference = reference / np.linalg.norm(reference)
    return M if np.sum(M * reference) > 0 else -M


def test_essential_matrix_fits_the_truth_and_flags_the_outliers(two_view_scene):
    cam, E_true, F_true, x1, x2, outlier = two_view_scene
    result = tessera.estimate_essential_matrix(x1, x2, cam, cam)
    assert result is not None
    E = result["E"]
    assert E.shape == (3, 3)
    np.testing.assert_allclose(normalized_up_to_sign(E, E_true), E_true / np.linalg.norm(E_true),
                               atol=0.03)
    # Two equal singular values and a zero one: an essential matrix.
    s = np.linalg.svd(E, compute_uv=False)
    assert s[2] < 1e-6 * s[0] and abs(s[0] - s[1]) < 1e-6 * s[0]
    mask = result["inlier_mask"]
    assert not mask[outlier].any()
    assert mask[~outlier].mean() > 0.97
    assert result["num_inliers"] == int(mask.sum())
    K_inv = np.linalg.inv(np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]]))
    assert np.median(epipolar_distance_px(K_inv.T @ E @ K_inv, x1[mask], x2[mask])) < 1.0


def test_fundamental_matrix_fits_the_truth_and_flags_the_outliers(two_view_scene):
    _, _, F_true, x1, x2, outlier = two_view_scene
    result = tessera.estimate_fundamental_matrix(x1, x2)
    assert result is not None
    F = result["F"]
    s = np.linalg.svd(F, compute_uv=False)
    assert s[2] < 1e-9 * s[0]  # rank 2
    mask = result["inlier_mask"]
    # F's seven degrees of freedom let a rare outlier fit: at most 3% of them.
    assert mask[outlier].mean() < 0.03
    assert mask[~outlier].mean() > 0.97
    assert result["num_inliers"] == int(mask.sum())
    assert np.median(epipolar_distance_px(F, x1[mask], x2[mask])) < 1.0
    # The truth explains the true inliers F found.
    assert np.median(epipolar_distance_px(F_true, x1[mask & ~outlier], x2[mask & ~outlier])) < 1.0


def test_homography_fits_the_truth_and_flags_the_outliers():
    rng = np.random.default_rng(5)
    H_true = np.array([[1.1, 0.05, 20.0], [-0.03, 0.95, -10.0], [1e-4, -5e-5, 1.0]])
    x1 = rng.uniform([0, 0], [640, 480], (150, 2))

    def transfer(points):
        h = np.c_[points, np.ones(len(points))] @ H_true.T
        return h[:, :2] / h[:, 2:]

    x2 = transfer(x1) + rng.normal(0, NOISE_PX, (150, 2))
    outlier = rng.random(150) < OUTLIER_RATIO
    x2[outlier] += rng.uniform(20, 100, (outlier.sum(), 1)) * np.c_[
        np.cos(angles := rng.uniform(0, 2 * np.pi, outlier.sum())), np.sin(angles)]
    result = tessera.estimate_homography_matrix(x1, x2)
    assert result is not None
    H = result["H"] / result["H"][2, 2]
    np.testing.assert_allclose(H, H_true, rtol=0.02, atol=0.5)
    np.testing.assert_array_equal(result["inlier_mask"], ~outlier)
    h = np.c_[x1, np.ones(len(x1))] @ H.T
    errors = np.linalg.norm(h[:, :2] / h[:, 2:] - transfer(x1), axis=1)
    assert np.max(errors) < 1.0
    again = tessera.estimate_homography_matrix(x1, x2)
    np.testing.assert_array_equal(again["H"], result["H"])


def test_bad_input_is_refused_naming_the_argument(pose_scene):
    cam, _, points3D, pixels, _ = pose_scene
    with pytest.raises(TypeError, match=r"points2D must have shape \(N, 2\), not \(200, 3\)"):
        tessera.estimate_absolute_pose(points3D, points3D, cam)
    with pytest.raises(TypeError, match="points3D must be an"):
        tessera.estimate_absolute_pose(pixels, "points", cam)
    with pytest.raises(TypeError, match="points3D must be an"):
        tessera.estimate_absolute_pose(pixels, None, cam)
    bad = pixels.copy()
    bad[17, 1] = np.nan
    with pytest.raises(tessera.InputError, match="points2D row 17 holds a value that is not"):
        tessera.estimate_absolute_pose(bad, points3D, cam)
    with pytest.raises(tessera.InputError, match="points2D has 199 rows but points3D has 200"):
        tessera.estimate_absolute_pose(pixels[1:], points3D, cam)
    with pytest.raises(tessera.InputError, match="needs at least 3 correspondences, got 2"):
        tessera.estimate_absolute_pose(pixels[:2], points3D[:2], cam)
    with pytest.raises(TypeError, match="camera must be a tessera.Camera"):
        tessera.estimate_absolute_pose(pixels, points3D, "camera")
    with pytest.raises(tessera.InputError, match="has no key 'max_eror'.*'max_error'"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, {"ransac": {"max_eror": 4}})
    with pytest.raises(tessera.InputError, match="has no key 'threshold'"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, {"threshold": 4})
    with pytest.raises(tessera.InputError, match="refinement_options has no key 'iterations'"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, None, {"iterations": 4})
    with pytest.raises(tessera.InputError, match="refine_focal_length"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, None, {"refine_focal_length": True})
    with pytest.raises(TypeError, match="ransac option confidence must be a number"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, {"confidence": "high"})
    with pytest.raises(TypeError, match="max_num_trials must be a whole number"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, {"max_num_trials": 10.5})
    with pytest.raises(tessera.InputError, match="max_error"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, {"max_error": -1.0})
    with pytest.raises(tessera.InputError, match="confidence"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, {"confidence": 1.5})
    with pytest.raises(TypeError, match="estimation_options must be a dict"):
        tessera.estimate_absolute_pose(pixels, points3D, cam, [("max_error", 4)])
    x = pixels[:10]
    with pytest.raises(tessera.InputError, match="needs at least 8 correspondences, got 7"):
        tessera.estimate_fundamental_matrix(x[:7], x[:7])
    with pytest.raises(tessera.InputError, match="needs at least 5 correspondences, got 4"):
        tessera.estimate_essential_matrix(x[:4], x[:4], cam, cam)
    with pytest.raises(TypeError, match="camera2 must be a tessera.Camera"):
        tessera.estimate_essential_matrix(x, x, cam, None)
    with pytest.raises(tessera.InputError, match=r"points1 row 3 holds a value that is not"):
        tessera.estimate_homography_matrix(np.where(np.arange(10)[:, None] == 3, np.inf, x), x)
    with pytest.raises(TypeError, match=r"points2 must have shape \(N, 2\)"):
        tessera.estimate_homography_matrix(x, x.ravel())
    with pytest.raises(tessera.InputError, match="unknown camera model 'PINHOLE_X'"):
        tessera.Camera("PINHOLE_X", 640, 480, [500.0, 320.0, 240.0])


def test_two_view_geometry_verifies_the_matches(two_view_scene):
    cam, _, F_true, x1, x2, outlier = two_view_scene
    geometry = tessera.estimate_two_view_geometry(cam, x1, cam, x2)
    # A camera without a prior focal length: F, as the pipeline verifies such pairs.
    assert geometry["config"] == 3 and geometry["kind"] == "F"
    assert isinstance(geometry["cam2_from_cam1"], tessera.Rigid3d)
    inliers = geometry["inlier_matches"]
    assert inliers.dtype == np.uint32 and inliers.shape[1] == 2
    np.testing.assert_array_equal(inliers[:, 0], inliers[:, 1])  # row i matches row i
    kept = np.zeros(len(x1), dtype=bool)
    kept[inliers[:, 0]] = True
    assert kept[outlier].mean() < 0.03 and kept[~outlier].mean() > 0.97
    assert np.median(epipolar_distance_px(geometry["F"], x1[kept], x2[kept])) < 1.0
    # The same through explicit, shuffled matches into shuffled rows of points2.
    order = np.random.default_rng(2).permutation(len(x2))
    matches = np.c_[np.arange(len(x1)), np.argsort(order)]
    shuffled = tessera.estimate_two_view_geometry(cam, x1, cam, x2[order], matches)
    assert shuffled["config"] == 3
    assert abs(len(shuffled["inlier_matches"]) - len(inliers)) <= 2
    np.testing.assert_array_equal(order[shuffled["inlier_matches"][:, 1]],
                                  shuffled["inlier_matches"][:, 0])
    # Too few inliers for min_num_inliers: degenerate, no inliers.
    degenerate = tessera.estimate_two_view_geometry(cam, x1, cam, x2,
                                                    options={"min_num_inliers": 1000})
    assert degenerate["config"] == 1 and degenerate["kind"] is None
    assert degenerate["inlier_matches"].shape == (0, 2)


def test_two_view_geometry_flags_a_planar_pair_and_refuses_bad_input():
    rng = np.random.default_rng(9)
    cam = camera()
    H_true = np.array([[0.9, 0.02, 30.0], [0.01, 1.05, -20.0], [5e-5, 1e-5, 1.0]])
    x1 = rng.uniform([50, 50], [590, 430], (120, 2))
    h = np.c_[x1, np.ones(len(x1))] @ H_true.T
    x2 = h[:, :2] / h[:, 2:] + rng.normal(0, NOISE_PX, (120, 2))
    geometry = tessera.estimate_two_view_geometry(cam, x1, cam, x2, options={"random_seed": 4})
    assert geometry["kind"] == "H" and geometry["config"] == 6  # PLANAR_OR_PANORAMIC
    np.testing.assert_allclose(geometry["H"] / geometry["H"][2, 2], H_true, rtol=0.02, atol=0.5)
    with pytest.raises(tessera.InputError, match=r"matches row 1 \(5, 120\) is not a pair"):
        tessera.estimate_two_view_geometry(cam, x1, cam, x2, np.array([[0, 0], [5, 120]]))
    with pytest.raises(tessera.InputError, match="matches row 0 .-1, 0. is not a pair"):
        tessera.estimate_two_view_geometry(cam, x1, cam, x2, [[-1, 0]])
    with pytest.raises(TypeError, match=r"matches must be None or a \(K, 2\) array"):
        tessera.estimate_two_view_geometry(cam, x1, cam, x2, np.arange(6))
    with pytest.raises(tessera.InputError, match="points1 has 119 rows but points2 has 120"):
        tessera.estimate_two_view_geometry(cam, x1[1:], cam, x2)
    with pytest.raises(tessera.InputError, match="has no key 'dyn_num_trials_multiplier'"):
        tessera.estimate_two_view_geometry(cam, x1, cam, x2,
                                           options={"dyn_num_trials_multiplier": 2.0})
    with pytest.raises(tessera.InputError, match="max_H_inlier_ratio = 1.5"):
        tessera.estimate_two_view_geometry(cam, x1, cam, x2, options={"max_H_inlier_ratio": 1.5})
    with pytest.raises(TypeError, match="min_num_inliers must be a whole number"):
        tessera.estimate_two_view_geometry(cam, x1, cam, x2, options={"min_num_inliers": 1.5})
    with pytest.raises(TypeError, match="camera1 must be a tessera.Camera"):
        tessera.estimate_two_view_geometry(x1, x1, cam, x2)
