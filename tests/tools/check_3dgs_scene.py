#!/usr/bin/env python3
"""Checks a scene folder as the reference 3D Gaussian Splatting trainer
(graphdeco-inria/gaussian-splatting, scene/dataset_readers.py readColmapSceneInfo) loads
it: sparse/0/{cameras,images,points3D}.bin in COLMAP's binary layout, every camera
PINHOLE or SIMPLE_PINHOLE ("only undistorted datasets supported"), every image of
images.bin present in images/ with its camera's size, and points3D with positions and
colours. And the trainer's camera (readColmapCameras, getProjectionMatrix): the field of
view from the focal lengths alone, FovX = 2 atan(width / 2 fx) with the model's width,
and a symmetric frustum over the image as read, so its principal point is the centre of
the image file. Every point in front of every image must project with it within 0.5 px
of where the model's own camera projects it. Prints "N images, P points, worst
principal-point offset D px" and exits 0; else one line and exit 1.
usage: check_3dgs_scene.py SCENE_DIR [EXPECTED_NUM_IMAGES]"""
import math
import os
import struct
import sys

MAX_OFFSET_PX = 0.5


def fail(message):
    print(f"FAIL: {message}")
    sys.exit(1)


def read(f, fmt):
    size = struct.calcsize("<" + fmt)
    data = f.read(size)
    if len(data) != size:
        fail(f"{f.name}: truncated")
    return struct.unpack("<" + fmt, data)


def image_size(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] == b"\x89PNG\r\n\x1a\n":
        return struct.unpack(">II", data[16:24])
    if data[:2] == b"\xff\xd8":
        i = 2
        while i < len(data):
            marker, length = data[i + 1], struct.unpack(">H", data[i + 2:i + 4])[0]
            if marker in (0xC0, 0xC1, 0xC2):
                height, width = struct.unpack(">HH", data[i + 5:i + 9])
                return width, height
            i += 2 + length
    fail(f"{path}: not a JPEG or PNG image")


scene = sys.argv[1]
sparse = os.path.join(scene, "sparse", "0")
cameras = {}
with open(os.path.join(sparse, "cameras.bin"), "rb") as f:
    (num,) = read(f, "Q")
    for _ in range(num):
        camera_id, model, width, height = read(f, "iiQQ")
        num_params = {0: 3, 1: 4}.get(model)
        if num_params is None:
            fail(f"camera {camera_id} has model id {model}: only PINHOLE or SIMPLE_PINHOLE load")
        params = read(f, "d" * num_params)
        # (fx, fy, cx, cy): SIMPLE_PINHOLE is (f, cx, cy)
        cameras[camera_id] = (width, height, params if model == 1 else (params[0],) + params)
num_images = 0
poses = []  # (camera, image size, R, t) per image
with open(os.path.join(sparse, "images.bin"), "rb") as f:
    (num,) = read(f, "Q")
    for _ in range(num):
        pose = read(f, "i" + "d" * 7)
        (camera_id,) = read(f, "i")
        name = b""
        while (c := f.read(1)) not in (b"\x00", b""):
            name += c
        (num_points,) = read(f, "Q")
        f.read(24 * num_points)
        path = os.path.join(scene, "images", name.decode())
        if not os.path.isfile(path):
            fail(f"{path}: missing")
        if camera_id not in cameras:
            fail(f"image {name.decode()}: unknown camera {camera_id}")
        if image_size(path) != cameras[camera_id][:2]:
            fail(f"{path}: {image_size(path)} but its camera is {cameras[camera_id][:2]}")
        qw, qx, qy, qz = pose[1:5]
        rotation = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qw * qz), 2 * (qx * qz + qw * qy)],
                    [2 * (qx * qy + qw * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qw * qx)],
                    [2 * (qx * qz - qw * qy), 2 * (qy * qz + qw * qx), 1 - 2 * (qx * qx + qy * qy)]]
        poses.append((name.decode(), camera_id, image_size(path), rotation, pose[5:8]))
        num_images += 1
points = []
with open(os.path.join(sparse, "points3D.bin"), "rb") as f:
    (num_points,) = read(f, "Q")
    for _ in range(num_points):
        points.append(read(f, "Q" + "ddd" + "BBB" + "d")[1:4])
        (track_length,) = read(f, "Q")
        f.read(8 * track_length)
if num_points == 0:
    fail("no 3D points (the trainer initialises from them)")
if len(sys.argv) > 2 and num_images != int(sys.argv[2]):
    fail(f"{num_images} images, expected {sys.argv[2]}")

# The trainer's camera against the model's, over every point in front of every image.
worst, worst_where = 0.0, ""
for name, camera_id, (image_width, image_height), rotation, translation in poses:
    width, height, (fx, fy, cx, cy) = cameras[camera_id]
    fov_x, fov_y = 2 * math.atan(width / (2 * fx)), 2 * math.atan(height / (2 * fy))
    trainer_fx = image_width / (2 * math.tan(fov_x / 2))
    trainer_fy = image_height / (2 * math.tan(fov_y / 2))
    trainer_cx, trainer_cy = image_width / 2, image_height / 2
    for xyz in points:
        x, y, z = (sum(r * p for r, p in zip(row, xyz)) + t for row, t in zip(rotation, translation))
        if z <= 0:
            continue
        offset = math.hypot(trainer_fx * x / z + trainer_cx - (fx * x / z + cx),
                            trainer_fy * y / z + trainer_cy - (fy * y / z + cy))
        if offset > worst:
            worst, worst_where = offset, f"image {name} (camera {camera_id})"
if worst > MAX_OFFSET_PX:
    fail(f"{worst_where}: the trainer's camera (principal point at the image centre) projects "
         f"a point {worst:.2f} px from where the model's camera does (at most {MAX_OFFSET_PX})")
print(f"{num_images} images, {num_points} points, worst principal-point offset {worst:.4f} px")
