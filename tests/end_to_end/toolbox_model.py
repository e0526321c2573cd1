"""Edits and checks of COLMAP text models for toolbox_adjust_align_test.sh (pure Python):
  perturb MODEL OUT SHIFT DEG SEED     every pose moved by SHIFT (model units), turned by DEG
  transform MODEL OUT                  the model moved by the known similarity below
  check_similarity ALIGNMENT_JSON TOL  alignment.json against the known similarity
  up_angle MODEL                       the angle (deg) of the cameras' mean up from +Z
  same_poses A B                       exit 1 unless images.txt poses agree to 1e-12
  gps_distances MODEL TAGS             centres' distances (m) to their tags, in the frame
                                       of MODEL/georeference.json: prints mean max
  rename MODEL OUT                     every image renamed (no name shared)
"""
import json
import math
import os
import random
import shutil
import sys

# The known similarity: x_ref = S * R * x + T.
S = 2.5
AXIS, ANGLE = (0.3, -0.8, 0.52), 0.7
T = (3.0, -1.0, 12.0)


def normalize(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def quat_axis_angle(axis, angle):
    a = normalize(axis)
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), a[0] * s, a[1] * s, a[2] * s)


def qmul(p, q):
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def qconj(q):
    return (q[0], -q[1], -q[2], -q[3])


def rotate(q, v):
    return qmul(qmul(q, (0.0,) + tuple(v)), qconj(q))[1:]


def matrix(q):
    return [rotate(q, e) for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]  # columns


def read_images(model):
    """[(header fields, points line)] of images.txt, comments dropped."""
    lines = [l.rstrip("\n") for l in open(os.path.join(model, "images.txt"))
             if not l.startswith("#")]
    return [(lines[i].split(), lines[i + 1]) for i in range(0, len(lines) - 1, 2)]


def write_images(out, images):
    with open(os.path.join(out, "images.txt"), "w") as f:
        for fields, points in images:
            f.write(" ".join(fields) + "\n" + points + "\n")


def pose(fields):
    return tuple(map(float, fields[1:5])), tuple(map(float, fields[5:8]))


def set_pose(fields, q, t):
    fields[1:8] = [repr(x) for x in q + tuple(t)]


def centre(q, t):
    return tuple(-x for x in rotate(qconj(q), t))


def copy_model(model, out, same_frame=True):
    """The model's files; its georeference.json too when the frame stays."""
    os.makedirs(out, exist_ok=True)
    names = ["cameras.txt", "images.txt", "points3D.txt"]
    if same_frame and os.path.exists(os.path.join(model, "georeference.json")):
        names.append("georeference.json")
    for name in names:
        shutil.copy(os.path.join(model, name), out)


def perturb(model, out, shift, degrees, seed):
    rng = random.Random(int(seed))
    copy_model(model, out)
    images = read_images(model)
    for fields, _ in images:
        q, t = pose(fields)
        c = centre(q, t)
        d = normalize([rng.gauss(0, 1) for _ in range(3)])
        c = tuple(ci + float(shift) * di for ci, di in zip(c, d))
        dq = quat_axis_angle([rng.gauss(0, 1) for _ in range(3)], math.radians(float(degrees)))
        q = qmul(dq, q)
        set_pose(fields, q, [-x for x in rotate(q, c)])
    write_images(out, images)


def transform(model, out):
    copy_model(model, out, same_frame=False)
    qs = quat_axis_angle(AXIS, ANGLE)
    images = read_images(model)
    for fields, _ in images:
        q, t = pose(fields)
        q2 = qmul(q, qconj(qs))
        t2 = [S * ti - ri for ti, ri in zip(t, rotate(q2, T))]
        set_pose(fields, q2, t2)
    write_images(out, images)
    with open(os.path.join(out, "points3D.txt"), "w") as f:
        for line in open(os.path.join(model, "points3D.txt")):
            if line.startswith("#"):
                continue
            v = line.split()
            x = rotate(qs, tuple(map(float, v[1:4])))
            v[1:4] = [repr(S * xi + ti) for xi, ti in zip(x, T)]
            f.write(" ".join(v) + "\n")


def check_similarity(path, tolerance):
    a = json.load(open(path))
    r = matrix(quat_axis_angle(AXIS, ANGLE))  # columns
    error = abs(a["scale"] - S)
    error = max(error, max(abs(a["rotation"][i][j] - r[j][i]) for i in range(3) for j in range(3)))
    error = max(error, max(abs(a["translation"][i] - T[i]) for i in range(3)))
    print(f"alignment error {error:.3g} (scale {a['scale']!r})")
    sys.exit(0 if error <= float(tolerance) else 1)


def up_angle(model):
    up = [0.0, 0.0, 0.0]
    for fields, _ in read_images(model):
        q, _ = pose(fields)
        u = rotate(qconj(q), (0, -1, 0))
        up = [a + b for a, b in zip(up, u)]
    up = normalize(up)
    print(f"{math.degrees(math.acos(max(-1.0, min(1.0, up[2])))):.4f}")


def same_poses(a, b):
    pa = {f[-1]: tuple(map(float, f[1:8])) for f, _ in read_images(a)}
    pb = {f[-1]: tuple(map(float, f[1:8])) for f, _ in read_images(b)}
    # Within 1e-12: the reader normalises the quaternions this script wrote (the unit test
    # checks the held poses bit for bit in memory).
    same = pa.keys() == pb.keys() and all(
        max(abs(x - y) for x, y in zip(pa[k], pb[k])) <= 1e-12 for k in pa)
    sys.exit(0 if same and pa else 1)


def gps_distances(model, tags):
    geo = json.load(open(os.path.join(model, "georeference.json")))
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)

    def ecef(lat, lon, alt):
        lat, lon = math.radians(lat), math.radians(lon)
        n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
        return ((n + alt) * math.cos(lat) * math.cos(lon),
                (n + alt) * math.cos(lat) * math.sin(lon), (n * (1 - e2) + alt) * math.sin(lat))

    def enu(lat, lon, alt):
        o = ecef(geo["latitude"], geo["longitude"], geo["altitude"])
        d = [p - q for p, q in zip(ecef(lat, lon, alt), o)]
        la, lo = math.radians(geo["latitude"]), math.radians(geo["longitude"])
        return (-math.sin(lo) * d[0] + math.cos(lo) * d[1],
                -math.sin(la) * math.cos(lo) * d[0] - math.sin(la) * math.sin(lo) * d[1] +
                math.cos(la) * d[2],
                math.cos(la) * math.cos(lo) * d[0] + math.cos(la) * math.sin(lo) * d[1] +
                math.sin(la) * d[2])

    gps = {}
    for line in open(tags):
        name, lat, lon, alt = line.split()
        gps[name] = enu(float(lat), float(lon), float(alt))
    distances = []
    for fields, _ in read_images(model):
        q, t = pose(fields)
        c = centre(q, t)
        distances.append(math.dist(c, gps[fields[-1]]))
    print(f"{sum(distances) / len(distances):.4f} {max(distances):.4f}")


def rename(model, out):
    copy_model(model, out)
    images = read_images(model)
    for fields, _ in images:
        fields[-1] = "renamed_" + fields[-1]
    write_images(out, images)


if __name__ == "__main__":
    {"perturb": perturb, "transform": transform, "check_similarity": check_similarity,
     "up_angle": up_angle, "same_poses": same_poses, "gps_distances": gps_distances,
     "rename": rename}[sys.argv[1]](*sys.argv[2:])
