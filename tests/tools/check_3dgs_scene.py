#!/usr/bin/env python3
"""Checks a scene folder as the reference 3D Gaussian Splatting trainer
(graphdeco-inria/gaussian-splatting, scene/dataset_readers.py readColmapSceneInfo) loads
it: sparse/0/{cameras,images,points3D}.bin in COLMAP's binary layout, every camera
PINHOLE or SIMPLE_PINHOLE ("only undistorted datasets supported"), every image of
images.bin present in images/ with its camera's size, and points3D with positions and
colours. Prints "N images, P points" and exits 0; else one line and exit 1.
usage: check_3dgs_scene.py SCENE_DIR [EXPECTED_NUM_IMAGES]"""
import os
import struct
import sys


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
        read(f, "d" * num_params)
        cameras[camera_id] = (width, height)
num_images = 0
with open(os.path.join(sparse, "images.bin"), "rb") as f:
    (num,) = read(f, "Q")
    for _ in range(num):
        read(f, "i" + "d" * 7)
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
        if image_size(path) != cameras[camera_id]:
            fail(f"{path}: {image_size(path)} but its camera is {cameras[camera_id]}")
        num_images += 1
with open(os.path.join(sparse, "points3D.bin"), "rb") as f:
    (num_points,) = read(f, "Q")
    for _ in range(num_points):
        read(f, "Q" + "ddd" + "BBB" + "d")
        (track_length,) = read(f, "Q")
        f.read(8 * track_length)
if num_points == 0:
    fail("no 3D points (the trainer initialises from them)")
if len(sys.argv) > 2 and num_images != int(sys.argv[2]):
    fail(f"{num_images} images, expected {sys.argv[2]}")
print(f"{num_images} images, {num_points} points")
