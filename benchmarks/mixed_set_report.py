#!/usr/bin/env python3
"""Scores two workspaces of benchmarks/mixed_set.sh per scene.

usage: mixed_set_report.py NAME_MAP SHARED_DATASETS EXHAUSTIVE_WS RETRIEVAL_WS

NAME_MAP lines: "<shuffled name> <scene> <original name>". For each workspace: pairs
matched, models; per scene the images registered in the model holding most of that
scene, and the camera position (GT units and % of the scene's extent) and rotation
errors of those images after a similarity alignment (Umeyama) to the scene's ground
truth. Then the share of the exhaustive run's verified pairs that the retrieval run
also verified, overall and for pairs with at least 100 inliers.
"""
import json
import os
import sqlite3
import struct
import sys

import numpy as np

MAX_IMAGE_ID = 2147483647


def read_images_bin(path):
    """{name: (R_cam_from_world, t)} of a COLMAP binary images.bin."""
    poses = {}
    with open(path, "rb") as f:
        (count,) = struct.unpack("<Q", f.read(8))
        for _ in range(count):
            _, qw, qx, qy, qz, tx, ty, tz, _ = struct.unpack("<I7dI", f.read(64))
            name = b""
            while (c := f.read(1)) != b"\0":
                name += c
            (num_points,) = struct.unpack("<Q", f.read(8))
            f.seek(24 * num_points, os.SEEK_CUR)
            q = np.array([qw, qx, qy, qz])
            q /= np.linalg.norm(q)
            w, x, y, z = q
            R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                          [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                          [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
            poses[name.decode()] = (R, np.array([tx, ty, tz]))
    return poses


def read_ground_truth(datasets, scene):
    """{original name: (R_cam_from_world, camera centre)}, or {} without ground truth."""
    root = os.path.join(datasets, scene)
    truth = {}
    if os.path.isdir(os.path.join(root, "gt")):
        for file in os.listdir(os.path.join(root, "gt")):
            rows = [list(map(float, line.split()))
                    for line in open(os.path.join(root, "gt", file)) if line.strip()]
            R_world_from_cam = np.array(rows[4:7])
            truth[file[: -len(".camera")]] = (R_world_from_cam.T, np.array(rows[7]))
    elif os.path.isfile(os.path.join(root, "transforms.json")):
        data = json.load(open(os.path.join(root, "transforms.json")))
        for frame in data["frames"]:
            M = np.array(frame["transform_matrix"])
            R_world_from_cam = M[:3, :3] @ np.diag([1, -1, -1])  # OpenGL -> OpenCV axes
            truth[os.path.basename(frame["file_path"])] = (R_world_from_cam.T, M[:3, 3])
    return truth


def lookup(truth, name):
    if name in truth:
        return truth[name]
    stem = os.path.splitext(name)[0]
    return truth.get(stem)  # transforms.json often lists names without extension


def umeyama(source, target):
    """s, R, t minimising |target - (s R source + t)|."""
    mu_s, mu_t = source.mean(0), target.mean(0)
    xs, xt = source - mu_s, target - mu_t
    U, S, Vt = np.linalg.svd(xt.T @ xs / len(source))
    D = np.eye(3)
    if np.linalg.det(U) * np.linalg.det(Vt) < 0:
        D[2, 2] = -1
    R = U @ D @ Vt
    s = np.trace(np.diag(S) @ D) / xs.var(0).sum()
    return s, R, mu_t - s * R @ mu_s


def verified_pairs(db):
    connection = sqlite3.connect(db)
    rows = connection.execute(
        "SELECT pair_id, rows FROM two_view_geometries WHERE rows >= 15 AND config NOT IN (0, 1)")
    pairs = dict(rows.fetchall())
    num_matched = connection.execute("SELECT COUNT(*) FROM matches").fetchone()[0]
    return pairs, num_matched


def main():
    name_map, datasets, workspaces = sys.argv[1], sys.argv[2], sys.argv[3:]
    scene_of, original_of = {}, {}
    for line in open(name_map):
        shuffled, scene, original = line.split()
        scene_of[shuffled], original_of[shuffled] = scene, original
    scenes = sorted(set(scene_of.values()))
    count = {s: sum(1 for v in scene_of.values() if v == s) for s in scenes}
    results = {}
    # Each workspace is a bench row's folder, named after its manifest; the first is the
    # baseline the others' pairs are compared with.
    labels = [os.path.basename(os.path.normpath(ws)) for ws in workspaces]
    for label, ws in zip(labels, workspaces):
        pairs, num_matched = verified_pairs(os.path.join(ws, "database.db"))
        models = []
        sparse = os.path.join(ws, "sparse")
        if os.path.isdir(sparse):
            for d in sorted(os.listdir(sparse), key=lambda x: int(x) if x.isdigit() else 1 << 30):
                if os.path.isfile(os.path.join(sparse, d, "images.bin")):
                    models.append(read_images_bin(os.path.join(sparse, d, "images.bin")))
        results[label] = (pairs, num_matched)
        print(f"## {label}: {num_matched} pairs matched, {len(pairs)} verified, "
              f"{len(models)} models of {[len(m) for m in models]} images")
        print("| scene | images | models holding it | registered (best model) | "
              "position error mean | position error % extent | rotation error mean deg | "
              "rotation error max deg |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        for scene in scenes:
            per_model = [sum(1 for n in m if scene_of.get(n) == scene) for m in models]
            holding = sum(1 for c in per_model if c > 0)
            best = int(np.argmax(per_model)) if models else -1
            registered = per_model[best] if models else 0
            truth = read_ground_truth(datasets, scene)
            errors = "| - | - | - | -"
            if models and truth and registered >= 3:
                names = [n for n in models[best] if scene_of.get(n) == scene
                         and lookup(truth, original_of[n]) is not None]
                if len(names) >= 3:
                    est_centres = np.array([-models[best][n][0].T @ models[best][n][1] for n in names])
                    gt = [lookup(truth, original_of[n]) for n in names]
                    gt_centres = np.array([g[1] for g in gt])
                    s, R, t = umeyama(est_centres, gt_centres)
                    aligned = (s * (R @ est_centres.T)).T + t
                    position = np.linalg.norm(aligned - gt_centres, axis=1)
                    extent = np.linalg.norm(gt_centres.max(0) - gt_centres.min(0))
                    rotation = []
                    for n, g in zip(names, gt):
                        # cam_from_world of the aligned model: R_est R^T
                        R_aligned = models[best][n][0] @ R.T
                        cos = (np.trace(R_aligned @ g[0].T) - 1) / 2
                        rotation.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
                    errors = (f"| {position.mean():.4g} | {100 * position.mean() / extent:.2f} "
                              f"| {np.mean(rotation):.3f} | {np.max(rotation):.3f}")
            print(f"| {scene} | {count[scene]} | {holding} | {registered} {errors} |")
    base_pairs, base_matched = results[labels[0]]
    strong = [p for p, r in base_pairs.items() if r >= 100]
    for label in labels[1:]:
        pairs, matched = results[label]
        found = sum(1 for p in base_pairs if p in pairs)
        found_strong = sum(1 for p in strong if p in pairs)
        print(f"pairs matched: {label} {matched} = "
              f"{100 * matched / max(1, base_matched):.1f}% of {labels[0]}'s {base_matched}")
        print(f"{labels[0]}'s verified pairs found by {label}: {found} of {len(base_pairs)} "
              f"({100 * found / max(1, len(base_pairs)):.1f}%); with >= 100 inliers: "
              f"{found_strong} of {len(strong)} ({100 * found_strong / max(1, len(strong)):.1f}%)")

if __name__ == "__main__":
    main()
