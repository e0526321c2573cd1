"""The pickle fuzz's child (test_pickle_fuzz.py runs it in its own process, so that a crash
fails the test instead of ending pytest): mutated pickles and states of a small
Reconstruction and its Camera, Image and Point3D, each loaded; only InputError, TypeError,
ValueError and the unpickler's own errors may come out. What loads is then used
(calibration_matrix, img_from_cam, project, statistics, write and a read back), and the
setters and the model's edits (add_point3D, delete_observation, ...) are given random
values. Prints the counts as JSON.

usage: fuzz_pickle_states.py SEED MUTATIONS FOLDER"""

import copy
import json
import math
import pickle
import random
import resource
import sys

import numpy as np

import tessera

# What a pickle whose bytes were changed may raise before any state is read.
UNPICKLER_ERRORS = (pickle.UnpicklingError, EOFError, AttributeError, ImportError, KeyError,
                    IndexError, OverflowError, MemoryError, RecursionError, NameError,
                    UnicodeDecodeError)
STATE_ERRORS = (tessera.InputError, TypeError, ValueError)
ADDRESS_SPACE = 4 << 30  # bytes: the interpreter, numpy and the module need well under it


def small_model():
    """Two cameras, three images, four points: every part of a state."""
    cameras = [(1, "PINHOLE", 640, 480, [500.0, 500.0, 320.0, 240.0]),
               (2, "OPENCV", 800, 600, [600.0, 610.0, 400.0, 300.0, 0.01, -0.02, 0.0, 0.001])]
    keypoints = [(100.0 + 10 * k, 120.0 + 5 * k, k if k < 4 else 2**64 - 1) for k in range(6)]
    images = [(1, 1, "a.jpg", True, (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0), keypoints),
              (2, 2, "b/c.jpg", True, (0.0, 0.1, 0.0, math.sqrt(0.99)), (-1.0, 0.0, 0.2),
               keypoints),
              (3, 1, "d.jpg", False, (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0), [])]
    points = [(k, ((0.1 * k, 0.2, 4.0 + k), (10 * k, 20, 30), 0.5 + 0.1 * k,
                   [(1, k), (2, k)])) for k in range(4)]
    rec = tessera.Reconstruction.__new__(tessera.Reconstruction)
    rec.__setstate__((cameras, images, points))
    return rec


def random_value(rng, depth=0):
    choice = rng.randrange(14 if depth < 2 else 11)
    if choice == 0:
        return rng.choice([0, 1, -1, 2, 255, 256, 2**31 - 1, 2**32 - 1, 2**32, 2**63, 2**64 - 1,
                           2**64, -2**63, 10**30])
    if choice == 1:
        return rng.choice([0.0, -0.0, 1.0, -1.0, 1e-300, 1e308, float("nan"), float("inf"),
                           -float("inf"), 0.5])
    if choice == 2:
        return rng.choice(["", "PINHOLE", "OPENCV", "SIMPLE_RADIAL", "FULL_OPENCV", "NOPE",
                           "\ud800", "a\nb", "/abs.jpg", "../up.jpg", "x" * 1000])
    if choice == 3:
        return None
    if choice == 4:
        return rng.choice([True, False])
    if choice == 5:
        return b"\x00\xff"
    if choice == 6:
        return rng.uniform(-1e6, 1e6)
    if choice == 7:
        return rng.randrange(-2**70, 2**70)
    if choice == 8:
        return {"k": 1}
    if choice == 9:
        return object()
    if choice == 10:
        return rng.randrange(0, 10)
    length = rng.randrange(0, 9)
    items = [random_value(rng, depth + 1) for _ in range(length)]
    return items if choice == 11 else tuple(items) if choice == 12 else set()


def mutate(rng, value, depth=0):
    """`value` (a state) with one part replaced, dropped, duplicated or added to."""
    if not isinstance(value, (list, tuple)) or (depth > 0 and rng.random() < 0.3):
        return random_value(rng)
    items = list(value)
    action = rng.randrange(6)
    if not items or action == 0:
        items.append(random_value(rng))
    elif action == 1:
        del items[rng.randrange(len(items))]
    elif action == 2:
        items.insert(rng.randrange(len(items)), copy.deepcopy(items[rng.randrange(len(items))]))
    else:
        index = rng.randrange(len(items))
        items[index] = mutate(rng, items[index], depth + 1)
    return items if isinstance(value, list) and rng.random() < 0.9 else tuple(items)


def flip_bytes(rng, data):
    data = bytearray(data)
    for _ in range(rng.randrange(1, 4)):
        data[rng.randrange(len(data))] = rng.randrange(256)
    return bytes(data)


def use(value, folder, counts, write):
    """Calls on what loaded; only the errors of bad values are allowed."""
    points = np.array([[0.1, -0.2, 2.0], [0.0, 0.0, -1.0]])
    cameras = []
    if isinstance(value, tessera.Camera):
        cameras = [value]
    elif isinstance(value, tessera.Image):
        value.cam_from_world.matrix()
        value.projection_center()
        _ = value.keypoints, value.point3D_ids, value.num_points3D()
    elif isinstance(value, tessera.Point3D):
        _ = value.xyz, value.color, value.track, value.error
    elif isinstance(value, tessera.Reconstruction):
        cameras = list(value.cameras.values())
        value.statistics()
        value.compute_mean_reprojection_error()
        value.summary()
        for image_id in value.images:
            value.project(image_id, points)
        for point in value.points3D.values():
            _ = point.track, point.xyz
    for camera in cameras:
        camera.calibration_matrix()
        camera.img_from_cam(points)
        camera.img_from_cam(points[0])
    if write and isinstance(value, tessera.Reconstruction):
        target = f"{folder}/{counts['written'] + counts['not_written']}"
        try:
            value.write(target)
        except STATE_ERRORS:  # a model the reader would refuse is not written
            counts["not_written"] += 1
            return
        counts["written"] += 1
        tessera.Reconstruction(target)  # Tessera's reader takes what it wrote


def an_id(rng):
    """Mostly an id or index the small model has, sometimes any value."""
    return rng.randrange(6) if rng.random() < 0.8 else random_value(rng)


def edit_randomly(rng, rec, counts):
    """One of pycolmap's edits with random arguments: it keeps the model's invariants or
    raises a bad value's error (the model then unchanged)."""
    camera = tessera.Camera("PINHOLE", 640, 480, [500.0, 500.0, 320.0, 240.0],
                            camera_id=rng.choice([1, 5]))
    edits = [
        lambda: rec.add_camera(camera),
        lambda: rec.add_image(tessera.Image(name=rng.choice(["a.jpg", "new.jpg"]),
                                            points2D=np.zeros((rng.randrange(3), 2)),
                                            camera_id=an_id(rng), image_id=an_id(rng))),
        lambda: rec.register_image(an_id(rng)),
        lambda: rec.deregister_image(an_id(rng)),
        lambda: rec.add_point3D(random_value(rng) if rng.random() < 0.2 else [0.0, 0.0, 1.0],
                                [(an_id(rng), an_id(rng)) for _ in range(rng.randrange(4))]),
        lambda: rec.add_observation(an_id(rng), (an_id(rng), an_id(rng))),
        lambda: rec.delete_observation(an_id(rng), an_id(rng)),
        lambda: rec.delete_point3D(an_id(rng)),
    ]
    held = list(rec.points3D.values())  # objects a deletion must leave valid
    try:
        rng.choice(edits)()
        counts["edited"] += 1
    except STATE_ERRORS:
        pass
    for point in held:
        _ = point.xyz, point.track


def set_randomly(rng, value, counts):
    """A setter given a random value: it takes it or raises a bad value's error."""
    if isinstance(value, tessera.Reconstruction) and rng.random() < 0.5:
        edit_randomly(rng, value, counts)
        return
    target = None
    if isinstance(value, tessera.Reconstruction) and value.cameras and rng.random() < 0.5:
        target, name = next(iter(value.cameras.values())), "params"
    elif isinstance(value, tessera.Reconstruction) and value.points3D:
        target, name = next(iter(value.points3D.values())), "xyz"
    elif isinstance(value, tessera.Camera):
        target, name = value, "params"
    elif isinstance(value, tessera.Point3D):
        target, name = value, "xyz"
    if target is None:
        return
    try:
        setattr(target, name, random_value(rng))
    except STATE_ERRORS:
        pass


def main():
    seed, mutations, folder = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    # A flipped byte can make pickle's memo index a billion: CPython's unpickler then grows
    # its memo table to it (18 GB resident, seed 59, mutation 9714). The address space is
    # capped so that it fails as a MemoryError, an unpickler error, on any machine.
    hard = resource.getrlimit(resource.RLIMIT_AS)[1]
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, hard))
    rng = random.Random(seed)
    rec = small_model()
    originals = [rec, rec.cameras[2], rec.images[2], rec.points3D[1]]
    states = [value.__getstate__() for value in originals]
    pickles = [pickle.dumps(value) for value in originals]
    counts = {"loaded": 0, "refused": 0, "unpickler": 0, "written": 0,
              "not_written": 0, "edited": 0}
    for k in range(mutations):
        which = rng.randrange(len(originals))
        cls = type(originals[which])
        try:
            if k % 2 == 0:
                try:
                    value = pickle.loads(flip_bytes(rng, pickles[which]))
                except STATE_ERRORS:
                    raise
                except UNPICKLER_ERRORS:
                    counts["unpickler"] += 1
                    continue
            else:
                value = cls.__new__(cls)
                value.__setstate__(mutate(rng, states[which]))
        except STATE_ERRORS:
            counts["refused"] += 1
            continue
        if not isinstance(value, (tessera.Camera, tessera.Image, tessera.Point3D,
                                  tessera.Reconstruction)):
            continue  # a flip that made the pickle another object
        # Every pickle calls a factory that checks the state (never a bare __new__), so
        # whatever loaded is a whole object.
        repr(value)
        counts["loaded"] += 1
        # Writing every survivor would take long: a few hundred are written.
        use(value, folder, counts, write=counts["written"] < 300)
        set_randomly(rng, value, counts)
        # An edited model is written and read back too (the reader refuses what breaks
        # an invariant).
        use(value, folder, counts, write=isinstance(value, tessera.Reconstruction) and
            counts["written"] < 400)
    # A state set again on a live object, a camera of a model included.
    for value in (rec.cameras[1], rec.images[1], rec.points3D[0], rec):
        try:
            value.__setstate__(mutate(rng, value.__getstate__()))
        except (*STATE_ERRORS, RuntimeError):
            pass
    print(json.dumps(counts))


if __name__ == "__main__":
    main()
