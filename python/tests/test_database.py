"""tessera.Database on the CLI's workspace of the sample: the keypoints the model's
images hold, matches in the caller's order, inliers among the matches, geometry kinds."""

import shutil
import sqlite3
import struct

import numpy as np
import pytest

import tessera


def test_images_cameras_keypoints_and_descriptors(sample):
    _, _, output = sample
    database = tessera.Database(output / "database.db")
    model = tessera.Reconstruction(output / "sparse" / "0")
    assert len(database.images) == 11
    assert list(database.cameras) == list(model.cameras)
    for image_id, image in model.images.items():
        assert database.images[image_id].name == image.name
        keypoints = database.keypoints(image_id)
        assert keypoints.shape == (len(image.keypoints), 6) and keypoints.dtype == np.float32
        # The model's keypoints are the database's, as the mapper read them.
        np.testing.assert_array_equal(keypoints[:, :2].astype(np.float64), image.keypoints)
        descriptors = database.descriptors(image_id)
        assert descriptors.shape == (len(keypoints), 32) and descriptors.dtype == np.uint8
        assert not keypoints.flags.owndata and not descriptors.flags.owndata


def test_matches_and_two_view_geometries(sample):
    _, _, output = sample
    database = tessera.Database(output / "database.db")
    pairs = database.matched_pairs()
    assert len(pairs) == 55 and all(id1 < id2 for id1, id2 in pairs)
    id1, id2 = pairs[0]
    matches = database.matches(id1, id2)
    assert matches.shape[1] == 2 and len(matches) > 0
    np.testing.assert_array_equal(database.matches(id2, id1), matches[:, ::-1])
    geometries = database.two_view_geometries()
    assert len(geometries) == 55
    verified = [g for g in geometries if g["kind"] is not None]
    assert len(verified) >= 10
    assert {g["kind"] for g in verified} <= {"E", "F", "H"}
    for geometry in verified:
        inliers = {tuple(row) for row in geometry["inlier_matches"]}
        matched = {tuple(row) for row in database.matches(geometry["image_id1"],
                                                          geometry["image_id2"])}
        assert len(inliers) >= 15 and inliers <= matched
    single = database.two_view_geometry(verified[0]["image_id1"], verified[0]["image_id2"])
    np.testing.assert_array_equal(single["inlier_matches"], verified[0]["inlier_matches"])
    assert all(isinstance(g["cam2_from_cam1"], tessera.Rigid3d) for g in geometries)


def test_a_relative_pose_no_rotation_fits_is_refused_naming_the_pair(sample, tmp_path):
    copy = tmp_path / "database.db"
    shutil.copyfile(sample[2] / "database.db", copy)
    pair_id = 2147483647 * 1 + 2  # COLMAP's pair id of images 1 and 2
    with sqlite3.connect(copy) as connection:
        connection.execute("UPDATE two_view_geometries SET qvec = ?, tvec = ? WHERE pair_id = ?",
                           (struct.pack("4d", 0.5, 0, 0, 0), struct.pack("3d", 1, 2, 3),
                            pair_id))
    connection.close()
    with pytest.raises(tessera.InputError,
                       match="two-view geometry of images 1 and 2: cam2_from_cam1 is not a "
                             "unit quaternion"):
        tessera.Database(copy).two_view_geometry(1, 2)
    # COLMAP leaves qvec at zero where it has no relative pose: the identity rotation.
    with sqlite3.connect(copy) as connection:
        connection.execute("UPDATE two_view_geometries SET qvec = ? WHERE pair_id = ?",
                           (struct.pack("4d", 0, 0, 0, 0), pair_id))
    connection.close()
    pose = tessera.Database(copy).two_view_geometry(1, 2)["cam2_from_cam1"]
    assert pose == tessera.Rigid3d(tessera.Rotation3d(), [1.0, 2.0, 3.0])


def test_a_file_that_is_not_a_database_raises_input_error(sample, tmp_path):
    not_a_database = tmp_path / "not_a.db"
    not_a_database.write_text("hello")
    with pytest.raises(tessera.InputError, match="not_a.db"):
        tessera.Database(not_a_database)


def test_database_arrays_are_read_only(sample):
    database = tessera.Database(sample[2] / "database.db")
    image_id = next(iter(database.images))
    pair = database.matched_pairs()[0]
    for name, array in {"keypoints": database.keypoints(image_id),
                        "descriptors": database.descriptors(image_id),
                        "matches": database.matches(*pair),
                        "inlier_matches": database.two_view_geometry(*pair)["inlier_matches"]}.items():
        assert not array.flags.writeable, name
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 0


def test_pycolmap_reads_give_what_the_database_holds(sample):
    """pycolmap's read_* names: each gives what Tessera's own call gives; unknown ids and
    names are InputErrors naming them."""
    _, _, output = sample
    with tessera.Database.open(output / "database.db") as database:
        images = database.images
        assert database.num_images() == len(images) == 11
        assert [image.image_id for image in database.read_all_images()] == sorted(images)
        for image_id, image in images.items():
            assert database.exists_image(image_id)
            for read in (database.read_image(image_id),
                         database.read_image_with_name(image.name)):
                assert (read.image_id, read.name, read.camera_id) == (
                    image_id, image.name, image.camera_id)
                np.testing.assert_array_equal(read.keypoints, image.keypoints)
            np.testing.assert_array_equal(database.read_keypoints(image_id),
                                          database.keypoints(image_id))
            np.testing.assert_array_equal(database.read_descriptors(image_id).data,
                                          database.descriptors(image_id))
        assert not database.exists_image(999)
        with pytest.raises(tessera.InputError, match="read_image: image_id 999: the database "
                                                     "has no such image"):
            database.read_image(999)
        with pytest.raises(tessera.InputError, match="read_image_with_name: 'none.jpg': the "
                                                     "database has no such image"):
            database.read_image_with_name("none.jpg")
