#!/bin/bash
# GPS as a prior and a frame (issue 27, item 1) on a geotagged copy of fountain-P11
# (downscaled here to 768 px; GPS tags written by tessera_test_geotag from the
# ground-truth camera centres, taken as east/north/up metres about 46.52 N 6.57 E 400 m,
# with 0.25 m of noise in each axis). `fast.json` with use_gps_prior:
#  1. every image registered; sparse/0/georeference.json names the origin (the median of
#     the GPS positions) and the ENU frame; the camera centres of images.txt lie within
#     the GPS noise of their tags converted to that frame here, with no alignment; the
#     PLY and transforms.json say which frame they are in;
#  2. GPS that contradicts the images (each image tagged with another's position): the
#     model keeps its own frame, no georeference.json, a warning that says why;
#  1b. the global mapper, on the same matches, anchors its model the same way;
#  3. a GPS sigma of 0: exit 2 naming the option (both mappers);
#  and `eval --no-align` scores the anchored model in its own frame (the ground truth's
#  given by --gt-origin), and refuses a model without georeference.json or ground truth
#  without a frame.
# usage: georeference_test.sh TESSERA DOWNSCALE GEOTAG SHARED_DIR SOURCE_DIR
set -uo pipefail
source "$(dirname "$0")/common.sh"
start_fountain_gps_test "$@"

"$downscale" "$dataset/images" "$work/clean" 768 95 > /dev/null || fail "downscale"
cp -r "$work/clean" "$work/images"
"$geotag" "$work/images" "$dataset/gt" 46.52 6.57 400 --noise 0.25 --altitude-noise 0.25 \
  --seed 2 > "$work/geotag.txt" || fail "geotag"
python3 - "$source_dir/manifests/fast.json" "$work" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pipeline"]["mapper"] = {"plugin": "incremental", "options": {
    "use_gps_prior": True, "gps_horizontal_sigma": 0.25, "gps_vertical_sigma": 0.25}}
m["pipeline"]["exporters"] = [{"plugin": "colmap_text"}, {"plugin": "ply"},
                              {"plugin": "transforms_json"}]
json.dump(m, open(sys.argv[2] + "/gps.json", "w"))
m["pipeline"]["mapper"]["options"]["gps_horizontal_sigma"] = 0
json.dump(m, open(sys.argv[2] + "/zero.json", "w"))
m["pipeline"]["mapper"]["plugin"] = "global"
json.dump(m, open(sys.argv[2] + "/zero_global.json", "w"))
m["pipeline"]["mapper"]["options"]["gps_horizontal_sigma"] = 0.25
json.dump(m, open(sys.argv[2] + "/gps_global.json", "w"))
PY

# 1. Anchored.
"$tessera" run --images "$work/images" --output "$work/out" --manifest "$work/gps.json" \
  --threads 2 2> "$work/run.log" || { tail -20 "$work/run.log"; fail "tessera run"; }
grep "anchored to the GPS" "$work/run.log" || { tail -20 "$work/run.log"; fail "not anchored"; }
cat > "$work/check_anchored.py" <<'PY'
import json, math, os, sys
out, tags = sys.argv[1], sys.argv[2]
geo = json.load(open(os.path.join(out, "sparse/0/georeference.json")))
assert geo["frame"] == "ENU", geo
assert abs(geo["latitude"] - 46.52) < 1e-3 and abs(geo["longitude"] - 6.57) < 1e-3, geo
a, f = 6378137.0, 1 / 298.257223563
e2 = f * (2 - f)
def ecef(lat, lon, alt):
    lat, lon = math.radians(lat), math.radians(lon)
    n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
    return ((n + alt) * math.cos(lat) * math.cos(lon), (n + alt) * math.cos(lat) * math.sin(lon),
            (n * (1 - e2) + alt) * math.sin(lat))
def enu(lat, lon, alt):
    o = ecef(geo["latitude"], geo["longitude"], geo["altitude"])
    d = [p - q for p, q in zip(ecef(lat, lon, alt), o)]
    la, lo = math.radians(geo["latitude"]), math.radians(geo["longitude"])
    return (-math.sin(lo) * d[0] + math.cos(lo) * d[1],
            -math.sin(la) * math.cos(lo) * d[0] - math.sin(la) * math.sin(lo) * d[1] + math.cos(la) * d[2],
            math.cos(la) * math.cos(lo) * d[0] + math.cos(la) * math.sin(lo) * d[1] + math.sin(la) * d[2])
gps = {}
for line in open(tags):
    name, lat, lon, alt = line.split()
    gps[name] = enu(float(lat), float(lon), float(alt))
# The true centres: the ground truth's frame is east/north/up about 46.52, 6.57, 400.
def enu_of_truth(p):
    lat, lon = math.radians(46.52), math.radians(6.57)
    east = (-math.sin(lon), math.cos(lon), 0)
    north = (-math.sin(lat) * math.cos(lon), -math.sin(lat) * math.sin(lon), math.cos(lat))
    up = (math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat))
    o = ecef(46.52, 6.57, 400)
    x = [o[k] + p[0] * east[k] + p[1] * north[k] + p[2] * up[k] for k in range(3)]
    # back to latitude, longitude, altitude (Bowring), then into the model's frame
    r = math.hypot(x[0], x[1])
    la = math.atan2(x[2], r * (1 - e2))
    for _ in range(10):
        n = a / math.sqrt(1 - e2 * math.sin(la) ** 2)
        h = r / math.cos(la) - n
        la = math.atan2(x[2], r * (1 - e2 * n / (n + h)))
    return enu(math.degrees(la), math.degrees(math.atan2(x[1], x[0])), h)
truth = {}
for name in gps:
    centre = open(os.path.join(sys.argv[3], name + ".camera")).read().split("\n")[7].split()
    truth[name] = enu_of_truth([float(v) for v in centre])
lines = [l for l in open(os.path.join(out, "sparse/0/images.txt")) if not l.startswith("#")]
errors, to_gps = [], []
for header in lines[0::2]:
    v = header.split()
    qw, qx, qy, qz, tx, ty, tz = map(float, v[1:8])
    R = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
         [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
         [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]
    c = [-sum(R[r][k] * (tx, ty, tz)[r] for r in range(3)) for k in range(3)]
    errors.append(math.dist(c, truth[v[9]]))
    to_gps.append(math.dist(c, gps[v[9]]))
errors.sort()
to_gps.sort()
print("%d cameras, without alignment: to their GPS tag mean %.3f m, median %.3f m; to the true "
      "centre mean %.3f m, median %.3f m, max %.3f m (GPS noise 0.25 m per axis)"
      % (len(errors), sum(to_gps) / len(to_gps), to_gps[len(to_gps) // 2],
         sum(errors) / len(errors), errors[len(errors) // 2], errors[-1]))
assert len(errors) == 11, len(errors)
assert sum(errors) / len(errors) < 0.3 and errors[-1] < 0.6, errors
frames = json.load(open(os.path.join(out, "transforms.json")))
assert frames["georeference"]["frame"] == "ENU", frames.get("georeference")
assert b"comment frame: ENU metres" in open(os.path.join(out, "sparse/0/points3D.ply"), "rb").read(600)
PY
python3 "$work/check_anchored.py" "$work/out" "$work/geotag.txt" "$dataset/gt" ||
  fail "the model is not where its GPS says"
echo "anchored: georeference.json, centres within the GPS noise, PLY and transforms.json in ENU"
# 1b. The global mapper anchors its models the same way, on the same matches.
mkdir -p "$work/global" && cp "$work/out/database.db" "$work/global/" || fail "copy the database"
"$tessera" map --output "$work/global" --images "$work/images" --manifest "$work/gps_global.json" \
  --threads 2 2> "$work/global.log" || { tail -20 "$work/global.log"; fail "global map with GPS"; }
grep "anchored to the GPS" "$work/global.log" || { tail -20 "$work/global.log"; fail "global: not anchored"; }
python3 "$work/check_anchored.py" "$work/global" "$work/geotag.txt" "$dataset/gt" ||
  fail "global: the model is not where its GPS says"
echo "global mapper: anchored as well"
# eval --no-align: the ground truth's frame is ENU about the geotag origin.
"$tessera" eval "$work/out/sparse/0" "$dataset/gt" --no-align --gt-origin 46.52,6.57,400 --json \
  > "$work/noalign.json" || fail "eval --no-align"
python3 - "$work/noalign.json" <<'PY' || fail "eval --no-align: the figures"
import json, sys
r = json.load(open(sys.argv[1]))
print("eval --no-align: %d registered, position error mean %.3f m, median %.3f m; rotation %.3f deg"
      % (r["registered"], r["pos_mean"], r["pos_median"], r["rot_mean_deg"]))
assert r["registered"] == 11 and r["pos_mean"] < 0.3 and r["alignment_scale"] == 1, r
PY
code=0
"$tessera" eval "$work/out/sparse/0" "$dataset/gt" --no-align 2> "$work/noorigin.log" || code=$?
[ "$code" = 2 ] && grep -q "needs the ground truth's frame: give --gt-origin" "$work/noorigin.log" ||
  { cat "$work/noorigin.log"; fail "eval --no-align without the ground truth's frame: exit $code"; }

# 2. Contradicting GPS: each image tagged with the position of the image 5 after it.
python3 - "$dataset/gt" "$work/shuffled.txt" <<'PY'
import os, sys
names = sorted(n[:-len(".camera")] for n in os.listdir(sys.argv[1]) if n.endswith(".camera"))
centre = {n: open(os.path.join(sys.argv[1], n + ".camera")).read().split("\n")[7] for n in names}
with open(sys.argv[2], "w") as out:
    for i, n in enumerate(names):
        out.write("%s %s\n" % (n, centre[names[(i + 5) % len(names)]]))
PY
rm -rf "$work/images" && cp -r "$work/clean" "$work/images"
"$geotag" "$work/images" "$work/shuffled.txt" 46.52 6.57 400 > /dev/null || fail "geotag shuffled"
"$tessera" run --images "$work/images" --output "$work/bad" --manifest "$work/gps.json" \
  --threads 2 2> "$work/bad.log" || { tail -20 "$work/bad.log"; fail "tessera run, shuffled GPS"; }
grep -q "\[warning\] map: model 0 is not georeferenced (use_gps_prior): its GPS contradicts it" \
  "$work/bad.log" || { grep "map:" "$work/bad.log"; fail "no fallback warning"; }
[ ! -e "$work/bad/sparse/0/georeference.json" ] || fail "a contradicted model has a georeference"
code=0
"$tessera" eval "$work/bad/sparse/0" "$dataset/gt" --no-align --gt-origin 46.52,6.57,400 \
  2> "$work/unanchored.log" || code=$?
[ "$code" = 2 ] && grep -q "needs a model anchored to GPS" "$work/unanchored.log" ||
  { cat "$work/unanchored.log"; fail "eval --no-align of a model without georeference: exit $code"; }
grep -q "11 of 11 images registered" "$work/bad.log" || fail "the fallback model lost images"
echo "contradicting GPS: the model keeps its own frame, with a warning"

# 3. A sigma of 0.
code=0
"$tessera" map --output "$work/out" --manifest "$work/zero.json" 2> "$work/zero.log" || code=$?
[ "$code" = 2 ] && grep -q "pipeline.mapper.options.gps_horizontal_sigma" "$work/zero.log" ||
  { cat "$work/zero.log"; fail "sigma 0: exit $code"; }
code=0
"$tessera" map --output "$work/global" --manifest "$work/zero_global.json" 2> "$work/zero_global.log" ||
  code=$?
[ "$code" = 2 ] && grep -q "pipeline.mapper.options.gps_horizontal_sigma" "$work/zero_global.log" ||
  { cat "$work/zero_global.log"; fail "global, sigma 0: exit $code"; }
echo "PASS"
