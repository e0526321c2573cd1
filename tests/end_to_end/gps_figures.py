#!/usr/bin/env python3
"""Where a GPS-anchored model sits against its images' tags (issue 47, item 4).

usage: gps_figures.py OUTPUT TAGS [--label NAME] [--set-aside NAME,...]
  OUTPUT  a workspace whose sparse/0 holds images.txt (the colmap_text exporter) and
          georeference.json
  TAGS    the lines "NAME latitude longitude altitude" that tessera_test_geotag printed
  --set-aside  the images whose tags the anchoring must set aside (left out of "good")

Prints one line: the origin's distance from the median of the good tags (latitude,
longitude and altitude each, as numpy.median), and the camera centres' mean and largest
distance from their good tags, all in metres in the model's east-north-up frame. Exits 1
when the model is not georeferenced.
"""
import json
import math
import os
import statistics
import sys

A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)


def ecef(lat, lon, alt):
    lat, lon = math.radians(lat), math.radians(lon)
    n = A / math.sqrt(1 - E2 * math.sin(lat) ** 2)
    return ((n + alt) * math.cos(lat) * math.cos(lon), (n + alt) * math.cos(lat) * math.sin(lon),
            (n * (1 - E2) + alt) * math.sin(lat))


def enu(origin, lat, lon, alt):
    o = ecef(origin["latitude"], origin["longitude"], origin["altitude"])
    d = [p - q for p, q in zip(ecef(lat, lon, alt), o)]
    la, lo = math.radians(origin["latitude"]), math.radians(origin["longitude"])
    return (-math.sin(lo) * d[0] + math.cos(lo) * d[1],
            -math.sin(la) * math.cos(lo) * d[0] - math.sin(la) * math.sin(lo) * d[1]
            + math.cos(la) * d[2],
            math.cos(la) * math.cos(lo) * d[0] + math.cos(la) * math.sin(lo) * d[1]
            + math.sin(la) * d[2])


def centres(images_txt):
    lines = [l for l in open(images_txt) if not l.startswith("#")]
    out = {}
    for header in lines[0::2]:
        v = header.split()
        qw, qx, qy, qz, tx, ty, tz = map(float, v[1:8])
        r = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
             [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
             [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]
        out[v[9]] = [-sum(r[i][k] * (tx, ty, tz)[i] for i in range(3)) for k in range(3)]
    return out


def main(argv):
    out, tags_file = argv[1], argv[2]
    label, set_aside = out, set()
    rest = argv[3:]
    while rest:
        flag, value, rest = rest[0], rest[1], rest[2:]
        if flag == "--label":
            label = value
        elif flag == "--set-aside":
            set_aside = set(value.split(","))
    geo_file = os.path.join(out, "sparse/0/georeference.json")
    if not os.path.exists(geo_file):
        print("%s: not georeferenced (no %s)" % (label, geo_file))
        return 1
    origin = json.load(open(geo_file))
    tags = {}
    for line in open(tags_file):
        name, lat, lon, alt = line.split()
        tags[name] = (float(lat), float(lon), float(alt))
    good = {n: t for n, t in tags.items() if n not in set_aside}
    median = [statistics.median(t[k] for t in good.values()) for k in range(3)]
    origin_error = math.dist(enu(origin, *median), (0, 0, 0))
    model = centres(os.path.join(out, "sparse/0/images.txt"))
    distances = [math.dist(c, enu(origin, *good[n])) for n, c in model.items() if n in good]
    print("%s: %d of %d images registered; origin %.7f, %.7f, %.2f m is %.3f m from the median "
          "of the %d good tags; camera centres a mean %.3f m (max %.3f m) from their good tags"
          % (label, len(model), len(tags), origin["latitude"], origin["longitude"],
             origin["altitude"], origin_error, len(good), sum(distances) / len(distances),
             max(distances)))
    print("FIGURES %s origin_to_median_m=%.4f mean_centre_to_tag_m=%.4f max_centre_to_tag_m=%.4f"
          % (label, origin_error, sum(distances) / len(distances), max(distances)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
