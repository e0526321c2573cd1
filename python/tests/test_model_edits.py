"""pycolmap's building blocks on a Reconstruction (issue 59): adding and deleting cameras,
images, points and observations with the model's invariants kept (what write() saves, the
reader reads back); Python objects of deleted points stay valid; bundle_adjustment and
triangulate_points in place; align_reconstructions_via_proj_centers."""

import pickle
import shutil

import numpy as np
import pytest

import tessera


@pytest.fixture()
def model(sample):
    return tessera.Reconstruction(sample[2] / "sparse" / "0")


def check_invariants(rec):
    """Each keypoint's point has it in its track and the other way round; tracks hold
    registered images only."""
    for point3D_id, point in rec.points3D.items():
        for image_id, idx in point.track:
            assert rec.images[int(image_id)].registered
            assert rec.images[int(image_id)].point3D_ids[idx] == point3D_id
    for image_id, image in rec.images.items():
        for idx, point3D_id in enumerate(image.point3D_ids):
            if point3D_id != 2**64 - 1:
                assert [image_id, idx] in rec.points3D[int(point3D_id)].track.tolist()


def test_add_and_delete_points_and_observations(model, tmp_path):
    image_ids = model.reg_image_ids()
    first, second = model.images[image_ids[0]], model.images[image_ids[1]]
    free1 = int(np.flatnonzero(first.point3D_ids == 2**64 - 1)[0])
    free2 = int(np.flatnonzero(second.point3D_ids == 2**64 - 1)[0])
    before = len(model.points3D)
    track = tessera.Track()
    track.add_element(first.image_id, free1)
    track.add_element(second.image_id, free2)
    new_id = model.add_point3D([1.0, 2.0, 3.0], track, color=[10, 20, 30])
    assert new_id > max(key for key in model.points3D if key != new_id)
    assert len(model.points3D) == before + 1
    assert first.point3D_ids[free1] == new_id  # the image object sees the edit
    assert model.points3D[new_id].track.tolist() == [[first.image_id, free1],
                                                     [second.image_id, free2]]
    assert model.points3D[new_id].error == -1
    check_invariants(model)

    # A keypoint that observes a point already, an unknown image, an index out of range.
    with pytest.raises(tessera.InputError, match="already observes point3D"):
        model.add_point3D([0, 0, 1], [(first.image_id, free1)])
    with pytest.raises(tessera.InputError, match="image_id 999: the model has no such image"):
        model.add_point3D([0, 0, 1], [(999, 0)])
    with pytest.raises(tessera.InputError, match="no index 100000"):
        model.add_observation(new_id, (first.image_id, 100000))
    with pytest.raises(TypeError, match="track"):
        model.add_point3D([0, 0, 1], "1 2")
    with pytest.raises(tessera.InputError, match="not finite"):
        model.add_point3D([0, np.nan, 1], [])
    assert len(model.points3D) == before + 1  # a refused edit changes nothing

    # A third observation, then deleting observations down to two deletes the point.
    third = model.images[image_ids[2]]
    free3 = int(np.flatnonzero(third.point3D_ids == 2**64 - 1)[0])
    model.add_observation(new_id, tessera.TrackElement(third.image_id, free3))
    held = model.points3D[new_id]
    assert len(held.track) == 3
    model.delete_observation(third.image_id, free3)
    assert len(model.points3D[new_id].track) == 2
    model.delete_observation(first.image_id, free1)  # two left: the point goes
    assert new_id not in model.points3D
    assert second.point3D_ids[free2] == 2**64 - 1
    np.testing.assert_array_equal(held.xyz, [1.0, 2.0, 3.0])  # detached, still valid
    check_invariants(model)

    # delete_point3D clears every keypoint's reference.
    some_id, some_point = next(iter(model.points3D.items()))
    observers = some_point.track.tolist()
    model.delete_point3D(some_id)
    for image_id, idx in observers:
        assert model.images[image_id].point3D_ids[idx] == 2**64 - 1
    with pytest.raises(tessera.InputError, match=f"point3D_id {some_id}: the model has no"):
        model.delete_point3D(some_id)
    check_invariants(model)

    model.write(tmp_path / "edited")
    again = tessera.Reconstruction(tmp_path / "edited")
    assert len(again.points3D) == len(model.points3D)
    assert again.statistics()["num_observations"] == model.statistics()["num_observations"]
    assert pickle.loads(pickle.dumps(model)).statistics() == model.statistics()


def test_add_images_and_cameras_and_registration(model, tmp_path):
    camera = tessera.Camera("PINHOLE", 640, 480, [500, 500, 320, 240], camera_id=7)
    assert model.add_camera(camera) == 7
    with pytest.raises(tessera.InputError, match="camera_id 7: the model already has"):
        model.add_camera(camera)
    pose = tessera.Rigid3d(tessera.Rotation3d(), [0.0, 0.0, 1.0])
    image = tessera.Image(name="new.jpg", points2D=np.array([[10.0, 20.0], [30.0, 40.0]]),
                          cam_from_world=pose, camera_id=7, image_id=100)
    assert not image.registered
    assert [p.xy.tolist() for p in image.points2D] == [[10.0, 20.0], [30.0, 40.0]]
    assert model.add_image(image) == 100
    with pytest.raises(tessera.InputError, match="already has an image of that id"):
        model.add_image(image)
    twin = tessera.Image(name="new.jpg", camera_id=7, image_id=101)
    with pytest.raises(tessera.InputError, match="is already named 'new.jpg'"):
        model.add_image(twin)
    with pytest.raises(tessera.InputError, match="camera_id 8: the model has no such camera"):
        model.add_image(tessera.Image(name="x.jpg", camera_id=8, image_id=102))
    with pytest.raises(tessera.InputError, match="no image_id"):
        model.add_image(tessera.Image(name="y.jpg", camera_id=7))

    # Not registered: no observation, and write() leaves it out.
    old = model.reg_image_ids()[0]
    free = int(np.flatnonzero(model.images[old].point3D_ids == 2**64 - 1)[0])
    with pytest.raises(tessera.InputError, match=r"image 100 \(new.jpg\) is not registered"):
        model.add_point3D([0, 0, 2], [(100, 0), (old, free)])
    model.register_image(100)
    point_id = model.add_point3D([0, 0, 2], [(100, 0), (old, free)])
    assert model.images[100].cam_from_world == pose
    model.write(tmp_path / "with_new")
    again = tessera.Reconstruction(tmp_path / "with_new")
    assert again.find_image_with_name("new.jpg") is not None
    assert again.points3D[point_id].track.tolist() == [[100, 0], [old, free]]

    # Deregistering removes its observations (the 2-element point with them).
    num_before = model.num_reg_images()
    model.deregister_image(old)
    assert model.num_reg_images() == num_before - 1
    assert point_id not in model.points3D
    assert not np.any(model.images[old].point3D_ids != 2**64 - 1)
    check_invariants(model)


def test_bundle_adjustment_updates_the_model_in_place(sample, model):
    images, manifest, _ = sample
    image_id = model.reg_image_ids()[2]
    image = model.images[image_id]  # held through the adjustment
    original = image.cam_from_world
    # Nudge one pose; the adjustment pulls it back near where the points say it is.
    moved = tessera.Rigid3d(original.rotation, original.translation + [0.02, 0.0, 0.0])
    before = model.compute_mean_reprojection_error_from_scratch()
    model._update_from(_with_pose(model, image_id, moved))
    nudged = model.compute_mean_reprojection_error_from_scratch()
    assert nudged > before
    summary = tessera.bundle_adjustment(model, manifest=manifest)
    assert summary["mean_reprojection_error_after"] < nudged
    assert model.compute_mean_reprojection_error_from_scratch() < nudged
    assert image.cam_from_world != moved  # the held object sees the new pose
    with pytest.raises(tessera.InputError, match="pass manifest="):
        tessera.bundle_adjustment(model, options={"refine_focal_length": False})
    with pytest.raises(TypeError, match="reconstruction must be a tessera.Reconstruction"):
        tessera.bundle_adjustment("sparse/0")


def _with_pose(model, image_id, pose):
    state = list(model.__getstate__())
    images = []
    for image_state in state[1]:
        image_state = list(image_state)
        if image_state[0] == image_id:
            image_state[4] = tuple(pose.rotation.quat)
            image_state[5] = tuple(pose.translation)
        images.append(tuple(image_state))
    state[1] = images
    return tessera._tessera._reconstruction_from_state(tuple(state))


def test_triangulate_points_replaces_the_points(sample, model, tmp_path):
    images, manifest, cli = sample
    workspace = tmp_path / "workspace"
    workspace.mkdir()
    shutil.copy(cli / "database.db", workspace / "database.db")
    poses = {image.name: image.cam_from_world for image in model.images.values()}
    held = model.points3D[next(iter(model.points3D))]
    result = tessera.triangulate_points(model, workspace / "database.db", images,
                                        tmp_path / "out", manifest=manifest)
    assert result is model
    assert len(model.points3D) > 100
    assert model.compute_mean_reprojection_error() < 1.5
    for image in model.images.values():
        assert image.cam_from_world == poses[image.name]
    check_invariants(model)
    assert len(tessera.Reconstruction(tmp_path / "out").points3D) == len(model.points3D)
    # Nothing written there (SQLite's WAL files come with any reader).
    assert {p.name for p in workspace.iterdir()} <= {"database.db", "database.db-wal",
                                                     "database.db-shm"}
    _ = held.xyz  # an object of the old points stays valid
    # A model whose image ids are not the workspace's (as one read from elsewhere): the
    # images are matched by name and keep their own ids.
    state = list(pickle.loads(pickle.dumps(model)).__getstate__())
    state[1] = [(image_id + 100,) + tuple(rest) for image_id, *rest in state[1]]
    state[2] = [(point3D_id, (xyz, color, error, [(i + 100, k) for i, k in track]))
                for point3D_id, (xyz, color, error, track) in state[2]]
    renumbered = tessera._tessera._reconstruction_from_state(tuple(state))
    tessera.triangulate_points(renumbered, workspace / "database.db", images, tmp_path / "o1",
                               manifest=manifest)
    assert sorted(renumbered.images) == sorted(image_id + 100 for image_id in model.images)
    for image in renumbered.images.values():
        assert image.cam_from_world == poses[image.name]
    check_invariants(renumbered)
    assert len(renumbered.points3D) == len(model.points3D)
    # Keypoints that are not the workspace's: refused, the model left as it was.
    state[1] = [(image_id, *rest[:5], [(x, y, 2**64 - 1) for x, y, _ in rest[5][1:]])
                for image_id, *rest in state[1]]
    state[2] = []
    foreign = tessera._tessera._reconstruction_from_state(tuple(state))
    with pytest.raises(tessera.InputError, match="keypoints that are not the workspace's"):
        tessera.triangulate_points(foreign, workspace / "database.db", images, tmp_path / "o3",
                                   manifest=manifest)
    assert len(foreign.points3D) == 0
    with pytest.raises(tessera.InputError, match="database.db in a workspace folder"):
        tessera.triangulate_points(model, workspace / "colmap.db", images, tmp_path / "o2")
    (tmp_path / "a_file").write_text("not a folder")
    with pytest.raises(tessera.InputError, match="output_path: .*a_file is a file, not a folder"):
        tessera.triangulate_points(model, workspace / "database.db", images,
                                   tmp_path / "a_file" / "out")
    with pytest.raises(tessera.InputError, match="output_path: .*a_file is a file"):
        tessera.incremental_mapping(workspace / "database.db", images, tmp_path / "a_file")
    with pytest.raises(tessera.InputError, match="image_path: .*: no such folder"):
        tessera.global_mapping(workspace / "database.db", tmp_path / "none", tmp_path / "o4")
    with pytest.raises(tessera.InputError, match="clear_points=False"):
        tessera.triangulate_points(model, workspace / "database.db", images, tmp_path / "o2",
                                   clear_points=False)


def test_align_reconstructions_via_proj_centers(model):
    moved = pickle.loads(pickle.dumps(model))
    truth = tessera.Sim3d(2.5, tessera.Rotation3d([0.1, 0.2, 0.3, 0.9273618495495704]),
                          [1.0, -2.0, 0.5])
    moved.transform(truth)
    found = tessera.align_reconstructions_via_proj_centers(model, moved, 0.05)
    assert found is not None
    assert abs(found.scale - 2.5) < 1e-6
    np.testing.assert_allclose(found.matrix(), truth.matrix(), atol=1e-6)
    # Nothing in common: None, and the reason logged.
    empty = tessera.Reconstruction()
    assert tessera.align_reconstructions_via_proj_centers(model, empty, 0.05) is None
    with pytest.raises(tessera.InputError, match="max_proj_center_error"):
        tessera.align_reconstructions_via_proj_centers(model, moved, 0)


def test_deleting_while_iterating_visits_each_remaining_id_once(model):
    """The id maps iterate over a snapshot of their ids: deleting during a loop (the
    everyday filter) neither crashes nor skips, and ids deleted meanwhile are not given."""
    seen = []
    for point3D_id, point in model.points3D.items():
        seen.append(point3D_id)
        if point.error > 0.5 or len(point.track) < 3:
            model.delete_point3D(point3D_id)
    assert len(seen) == len(set(seen))
    assert all(point.error <= 0.5 and len(point.track) >= 3 for point in model.points3D.values())
    # Deleting an observation can delete a point not yet visited: it is skipped.
    visited = []
    for point3D_id in model.points3D:
        visited.append(point3D_id)
        image_id, idx = (int(v) for v in model.points3D[point3D_id].track[0])
        model.delete_observation(image_id, idx)
    assert set(visited) >= set(model.points3D.keys())
    for image_id in model.images:  # deregistering while iterating the images
        model.deregister_image(image_id)
    assert len(model.points3D) == 0 and model.num_reg_images() == 0
    check_invariants(model)
