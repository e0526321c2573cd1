#!/bin/bash
# Installs Tessera from BUILD_DIR into a temporary prefix and builds this folder's
# plugins, one of every kind (the akaze detector, the symmetric_ratio matcher, the
# window_stride pair selector, the strict mapper, the cauchy bundle adjuster and the
# bundler exporter),
# against the installed SDK alone. Then: `tessera plugins --json` lists all five as
# usable, from the out-of-tree build; akaze and symmetric_ratio extract and match three
# images; and ONE `tessera bench` run compares a row of bundled plugins (orb, exhaustive,
# brute_force, ceres) with a row of the five out-of-tree ones on the small fountain
# sample: both register all 11 images. The bundler export of the out-of-tree row must
# parse, hold the model's cameras and points, and reproject its points onto their views
# in Bundler's conventions.
# usage: build_and_run.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build_dir=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log"
# Only the installed tree: no path into the Tessera sources or build. The examples are
# built from the copy installed with the documentation, as the guide says, beside the
# guide and one page per plugin kind.
docs="$work/prefix/share/doc/tessera"
for page in plugin_authors_guide.md manifest_reference.md plugins/detector.md plugins/matcher.md \
    plugins/pair_selector.md plugins/mapper.md plugins/bundle_adjuster.md plugins/exporter.md; do
  [ -s "$docs/$page" ] || { echo "FAIL: $docs/$page is not installed"; exit 1; }
done
# The guide states the installed plugin.h's ABI, each bundled plugin's options page is
# installed, and every link of the installed pages resolves.
python3 "$source_dir/../../scripts/check_installed_docs.py" "$work/prefix" \
  --source "$source_dir/../.." || { echo "FAIL: the installed documentation"; exit 1; }
for example in "$source_dir"/*.cc "$source_dir"/CMakeLists.txt; do
  cmp -s "$example" "$docs/examples/$(basename "$example")" ||
    { echo "FAIL: $docs/examples/$(basename "$example") is not the installed copy of $example"; exit 1; }
done
cp -r "$docs/examples" "$work/examples"
cmake -S "$work/examples" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log"
cmake --build "$work/build" -j2 > "$work/build.log"

# The bundler exporter without `LIBRARIES Tessera::io`: tessera_add_plugin links with
# --no-undefined, so the build fails naming a missing symbol instead of producing a
# plugin that loads only where the host has Tessera::io loaded already.
mkdir -p "$work/unlinked"
cat > "$work/unlinked/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.25)
project(unlinked LANGUAGES CXX)
find_package(Tessera REQUIRED)
find_package(OpenCV 4 REQUIRED COMPONENTS core imgcodecs)
tessera_add_plugin(tessera_exporter_unlinked SOURCES $(cd "$(dirname "$0")" && pwd)/bundler_exporter.cc
                   LIBRARIES opencv_imgcodecs)
CMAKE
cmake -S "$work/unlinked" -B "$work/unlinked/build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  > "$work/unlinked.log" 2>&1 || { cat "$work/unlinked.log"; exit 1; }
if cmake --build "$work/unlinked/build" >> "$work/unlinked.log" 2>&1; then
  echo "a plugin using Tessera::io without linking it built"; exit 1
fi
grep -q "undefined reference to .*tessera::" "$work/unlinked.log" ||
  { cat "$work/unlinked.log"; echo "the failed build does not name the missing symbol"; exit 1; }
echo "a plugin using Tessera::io without linking it: the build fails naming the symbol"

cat > "$work/manifest.json" <<JSON
{
  "plugin_paths": ["build/plugins"],
  "pipeline": {
    "detector": {"plugin": "akaze", "options": {"max_num_features": 500}},
    "pair_selector": {"plugin": "exhaustive"},
    "matcher": {"plugin": "symmetric_ratio"}
  }
}
JSON
tessera="$work/prefix/bin/tessera"
"$tessera" plugins --json --manifest "$work/manifest.json" > "$work/plugins.json"
python3 - "$work/plugins.json" "$work/build/plugins" <<'PY' || { cat "$work/plugins.json"; exit 1; }
import json, os, sys
plugins = json.load(open(sys.argv[1]))["plugins"]
found = {(p["kind"], p["name"]): p for p in plugins if p["usable"]}
assert ("detector", "sift") in found, "bundled sift not found by the installed binary"
for kind, name in [("detector", "akaze"), ("matcher", "symmetric_ratio"),
                   ("pair_selector", "window_stride"), ("mapper", "strict"),
                   ("mapper", "stepwise_global"),
                   ("bundle_adjuster", "cauchy"), ("bundle_adjuster", "robust"),
                   ("bundle_adjuster", "pass_through"), ("exporter", "bundler")]:
    assert (kind, name) in found, "%s %s not listed as usable" % (kind, name)
    folder = os.path.dirname(os.path.realpath(found[(kind, name)]["file"]))
    assert folder == os.path.realpath(sys.argv[2]), (kind, name, folder)
print("plugins --json lists the nine out-of-tree plugins")
PY

# Out-of-tree plugins describe their options as the bundled ones do (TESSERA_PLUGIN_OPTIONS).
for described in "akaze threshold,max_num_features,max_image_size" "bundler folder"; do
  read -r name keys <<< "$described"
  "$tessera" plugins "$name" --json --manifest "$work/manifest.json" > "$work/$name.json"
  python3 - "$work/$name.json" "$keys" <<'PY' || { cat "$work/$name.json"; exit 1; }
import json, sys
options = json.load(open(sys.argv[1]))["options"]
names = [option["name"] for option in options or []]
assert names == sys.argv[2].split(","), names
assert all(option["help"] for option in options), "an option without help"
PY
done
echo "plugins NAME --json describes the options of akaze and bundler"

mkdir -p "$work/images"
examples="$source_dir/../../examples/fountain-P11-small/images"
cp "$examples/0004.jpg" "$examples/0005.jpg" "$examples/0006.jpg" "$work/images/"
{ "$tessera" extract --images "$work/images" --output "$work/out" --manifest "$work/manifest.json" &&
  "$tessera" match --output "$work/out" --manifest "$work/manifest.json"; } \
  2> "$work/run.log" || { cat "$work/run.log"; exit 1; }
cat "$work/run.log"
grep -q "3 detected with" "$work/run.log" || { echo "akaze did not detect 3 images"; exit 1; }
grep -Eq "3 pairs, 3 matched now" "$work/run.log" || { echo "pairs were not matched"; exit 1; }

# Contradictory options of the out-of-tree plugins: exit code 2, one line naming the key.
refuse() {  # refuse SLOT JSON EXPECTED
  sed "s|\"$1\": {[^}]*}|\"$1\": $2|" "$work/manifest.json" > "$work/bad.json"
  local rc=0
  "$tessera" match --output "$work/out" --manifest "$work/bad.json" 2> "$work/bad.log" || rc=$?
  [ "$rc" = 2 ] && grep -qF "$3" "$work/bad.log" || {
    echo "expected exit code 2 and '$3', got $rc:"; cat "$work/bad.log"; exit 1; }
}
refuse pair_selector '{"plugin": "window_stride", "options": {"window": 3, "stride": 2}}' \
  "pipeline.pair_selector.options.stride = 2 must be 0 or greater than window = 3"
refuse matcher '{"plugin": "symmetric_ratio", "options": {"cross_check": false}}' \
  "pipeline.matcher.options.cross_check = false contradicts symmetric = true"
# The mapper slot: options checked (the incremental options nested in the strict ones),
# and a plugin of another kind refused naming its kind.
cat > "$work/mapper_bad.json" <<JSON
{"plugin_paths": ["build/plugins"],
 "pipeline": {"mapper": {"plugin": "strict", "options": {"incremental": {"max_reg_trials": -1}}}}}
JSON
cat > "$work/mapper_kind.json" <<JSON
{"plugin_paths": ["build/plugins"], "pipeline": {"mapper": {"plugin": "akaze"}}}
JSON
for case in "mapper_bad:pipeline.mapper.options.incremental.max_reg_trials" \
            "mapper_kind:pipeline.mapper.plugin: plugin 'akaze'"; do
  rc=0
  "$tessera" match --output "$work/out" --manifest "$work/${case%%:*}.json" 2> "$work/bad.log" || rc=$?
  [ "$rc" = 2 ] && grep -qF "${case#*:}" "$work/bad.log" || {
    echo "expected exit code 2 and '${case#*:}', got $rc:"; cat "$work/bad.log"; exit 1; }
done
grep -qF "is a detector, not a mapper" "$work/bad.log" || { cat "$work/bad.log"; exit 1; }

# Two bundle adjusters in the default pipeline, on 4 images of the sample: `robust`, on
# the installed building blocks (Tessera::ceres) with the Huber loss chosen through their
# loss hook, and `pass_through`, which wraps the bundled `ceres` made through the host's
# services (Plugin::host()) and so must give the model `ceres` gives, byte for byte.
mkdir -p "$work/four"
cp "$examples/0004.jpg" "$examples/0005.jpg" "$examples/0006.jpg" "$examples/0007.jpg" "$work/four/"
adjuster() {  # adjuster NAME BUNDLE_ADJUSTER_JSON [PLUGIN_FOLDER]: $work/NAME.json, the
  # installed default manifest with this bundle adjuster
  python3 - "$work/prefix/share/tessera/manifests/default.json" "$work/$1.json" "$2" "${3:-}" <<'PY'
import json, sys
manifest = json.load(open(sys.argv[1]))
manifest["plugin_paths"] = ["build/plugins"] + ([sys.argv[4]] if sys.argv[4] else [])
manifest["pipeline"]["bundle_adjuster"] = json.loads(sys.argv[3])
json.dump(manifest, open(sys.argv[2], "w"))
PY
}
adjuster ceres '{"plugin": "ceres"}'
adjuster robust '{"plugin": "robust", "options": {"loss": "huber", "loss_scale": 2.0}}'
adjuster pass_through '{"plugin": "pass_through", "options": {"adjuster": "ceres"}}'
"$tessera" run --images "$work/four" --output "$work/ba_ceres" --manifest "$work/ceres.json" \
  2> "$work/ba_ceres.log" || { cat "$work/ba_ceres.log"; exit 1; }
for name in robust pass_through; do
  cp -r "$work/ba_ceres" "$work/ba_$name"
  "$tessera" map -v --output "$work/ba_$name" --manifest "$work/$name.json" \
    2> "$work/ba_$name.log" || { cat "$work/ba_$name.log"; exit 1; }
  python3 - "$work/ba_$name/mapping_summary.json" "$name" <<'PY' || { cat "$work/ba_$name.log"; exit 1; }
import json, sys
summary = json.load(open(sys.argv[1]))
registered = summary["models"][0]["num_images"]
assert registered == 4, "%s registered %d of 4 images" % (sys.argv[2], registered)
PY
done
grep -Eq "\[debug\] robust \(a bundle of [0-9]+ images.*\): huber loss: usable" "$work/ba_robust.log" ||
  { cat "$work/ba_robust.log"; echo "robust did not adjust with the Huber loss"; exit 1; }
grep -Eq "\[debug\] pass_through \(a bundle of [0-9]+ images.*\): passed on: usable" \
  "$work/ba_pass_through.log" || { cat "$work/ba_pass_through.log"; echo "pass_through did not log"; exit 1; }
for file in cameras.bin images.bin points3D.bin; do
  cmp "$work/ba_ceres/sparse/0/$file" "$work/ba_pass_through/sparse/0/$file" ||
    { echo "pass_through around ceres gave another $file than ceres"; exit 1; }
done
echo "robust (Tessera::ceres, Huber) registers 4 of 4; pass_through around ceres gives ceres' model"

# A mapper on the global mapper's public steps (docs/plugins/mapper.md): the sample's 11
# images, every step but retriangulation, then the finishing step.
python3 - "$work/prefix/share/tessera/manifests/global.json" "$work/stepwise.json" <<'PY'
import json, sys
manifest = json.load(open(sys.argv[1]))
manifest["plugin_paths"] = ["build/plugins"]
manifest["pipeline"]["mapper"]["plugin"] = "stepwise_global"
json.dump(manifest, open(sys.argv[2], "w"))
PY
"$tessera" run --images "$examples" --output "$work/stepwise" --manifest "$work/stepwise.json" \
  2> "$work/stepwise.log" || { cat "$work/stepwise.log"; exit 1; }
grep -q "stepwise: 1 model(s) without retriangulation" "$work/stepwise.log" &&
  ! grep -q "retriangulated" "$work/stepwise.log" ||
  { cat "$work/stepwise.log"; echo "stepwise_global did not run the steps it chose"; exit 1; }
python3 - "$work/stepwise/mapping_summary.json" <<'PY' || { cat "$work/stepwise.log"; exit 1; }
import json, sys
summary = json.load(open(sys.argv[1]))
model = summary["models"][0]
assert model["num_images"] == 11, model
# FinishModels' self-check against the view graph, as for every mapper.
assert model["view_graph_check"]["verified_pairs"] > 0, model["view_graph_check"]
PY
echo "stepwise_global (the global mapper's steps, one by one) registers 11 of 11"

# Through the host's services a crash in the wrapped adjuster is named as the host names
# a crash of its own plugins (exit code 4), and a wrong name, kind or option is one line
# naming both plugins (exit code 2), before any image is read.
adjuster crash '{"plugin": "pass_through", "options": {"adjuster": "failing_bundle_adjuster", "options": {"fail": "segv"}}}' \
  "$(cd "$build_dir" && pwd)/test_plugins/failing"
cp -r "$work/ba_ceres" "$work/ba_crash"
rc=0
"$tessera" map --output "$work/ba_crash" --manifest "$work/crash.json" 2> "$work/ba_crash.log" || rc=$?
[ "$rc" = 4 ] && grep -q "\[error\] plugin 'failing_bundle_adjuster' crashed (SIGSEGV) while adjusting a bundle of" \
  "$work/ba_crash.log" || { cat "$work/ba_crash.log"; echo "the wrapped crash: exit $rc, not named"; exit 1; }
# Its second crash on that bundle, then the bundle refused to it by name (exit code 2).
rc=0
"$tessera" map --output "$work/ba_crash" --manifest "$work/crash.json" 2> "$work/ba_crash.log" || rc=$?
[ "$rc" = 4 ] || { cat "$work/ba_crash.log"; echo "the second wrapped crash: exit $rc"; exit 1; }
rc=0
"$tessera" map --output "$work/ba_crash" --manifest "$work/crash.json" 2> "$work/ba_crash.log" || rc=$?
[ "$rc" = 2 ] && grep -q "\[error\] bundle adjuster 'failing_bundle_adjuster' crashed twice on a bundle of .* is not given it again" \
  "$work/ba_crash.log" || { cat "$work/ba_crash.log"; echo "the quarantined wrapped adjuster: exit $rc"; exit 1; }
for case in '{"adjuster": "cerez"}|no bundle_adjuster plugin '"'cerez'"'; did you mean '"'ceres'"'?' \
            '{"adjuster": "akaze"}|is a detector, not a bundle_adjuster' \
            '{"adjuster": "ceres", "options": {"loss": "l2"}}|pipeline.bundle_adjuster.options.options.loss: ' \
            '{"adjuster": "pass_through"}|plugin creation loops: '"'pass_through' -> 'pass_through'"; do
  adjuster bad "{\"plugin\": \"pass_through\", \"options\": ${case%%|*}}"
  rc=0
  "$tessera" map --output "$work/ba_crash" --manifest "$work/bad.json" 2> "$work/bad.log" || rc=$?
  line=$(grep -F "${case#*|}" "$work/bad.log" || true)
  [ "$rc" = 2 ] && [[ "$line" == *"plugin 'pass_through'"* ]] ||
    { cat "$work/bad.log"; echo "expected exit code 2 and one line with '${case#*|}' naming pass_through, got $rc"; exit 1; }
done
echo "pass_through: the wrapped adjuster's crash named, refused after two, a bad name, kind or option refused in one line"

# One bench: a row of bundled plugins next to a row of the five out-of-tree ones.
cat > "$work/bundled.json" <<JSON
{
  "pipeline": {
    "detector": {"plugin": "orb", "options": {"max_num_features": 2000}},
    "pair_selector": {"plugin": "exhaustive"},
    "matcher": {"plugin": "brute_force"},
    "bundle_adjuster": {"plugin": "ceres"},
    "exporters": [{"plugin": "colmap_binary"}]
  }
}
JSON
cat > "$work/third_party.json" <<JSON
{
  "plugin_paths": ["build/plugins"],
  "pipeline": {
    "detector": {"plugin": "akaze", "options": {"max_num_features": 2000}},
    "pair_selector": {"plugin": "window_stride", "options": {"window": 3, "stride": 5}},
    "matcher": {"plugin": "symmetric_ratio"},
    "mapper": {"plugin": "strict", "options": {"min_agreement": 0.8}},
    "bundle_adjuster": {"plugin": "cauchy"},
    "exporters": [{"plugin": "colmap_binary"}, {"plugin": "bundler"}]
  }
}
JSON
"$tessera" bench --images "$examples" --output "$work/bench" --json "$work/bench.json" \
  "$work/bundled.json" "$work/third_party.json" 2> "$work/bench.log" || { cat "$work/bench.log"; exit 1; }
python3 - "$work/bench.json" <<'PY' || exit 1
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
# Every plugin with its version, the exporters too: two rows that differ only in an
# exporter do not look alike.
assert [r["plugins"] for r in rows] == [
    "orb 1.0.0 / exhaustive 1.0.0 / brute_force 1.0.0 / incremental 1.0.0 / ceres 1.0.0 / "
    "colmap_binary 1.0.0",
    "akaze 1.0.0 / window_stride 1.0.0 / symmetric_ratio 1.0.0 / strict 1.0.0 / cauchy 1.0.0 / "
    "colmap_binary 1.0.0+bundler 1.0.0"], rows
for r in rows:
    assert r["exit_code"] == 0 and r["num_registered"] == 11, r
    print("%s: %d of 11 registered, %d points, %.3f px" % (
        r["manifest"], r["num_registered"], r["num_points3D"], r["mean_reprojection_error_px"]))
PY

# The bundler export of the out-of-tree row: Bundler v0.3 with the model's counts, images
# listed and copied, points in front of their cameras (Bundler's look down -z) and
# projecting onto their views (x right, y up, from the image centre).
python3 - "$work/bench.json" <<'PY' || exit 1
import json, math, os, sys
row = json.load(open(sys.argv[1]))["rows"][1]
folder = os.path.join(row["workspace"], "bundler")
lines = open(os.path.join(folder, "bundle.out")).read().splitlines()
assert lines[0] == "# Bundle file v0.3", lines[0]
num_cameras, num_points = map(int, lines[1].split())
assert num_cameras == row["num_registered"], (num_cameras, row["num_registered"])
assert num_points == row["num_points3D"], (num_points, row["num_points3D"])
assert len(lines) == 2 + 5 * num_cameras + 3 * num_points, len(lines)
numbers = lambda i: [float(v) for v in lines[i].split()]
cameras = []
for c in range(num_cameras):
    first = 2 + 5 * c
    f, k1, k2 = numbers(first)
    R = [numbers(first + 1 + r) for r in range(3)]
    t = numbers(first + 4)
    for a in range(3):
        for b in range(3):
            dot = sum(R[a][k] * R[b][k] for k in range(3))
            assert abs(dot - (a == b)) < 1e-9, (c, R)
    cameras.append((f, k1, k2, R, t))
listed = open(os.path.join(folder, "list.txt")).read().splitlines()
assert len(listed) == num_cameras, len(listed)
for name in listed:
    assert os.path.isfile(os.path.join(folder, name)), name
errors = []
for p in range(num_points):
    first = 2 + 5 * num_cameras + 3 * p
    X = numbers(first)
    rgb = [int(v) for v in lines[first + 1].split()]
    assert len(rgb) == 3 and all(0 <= v <= 255 for v in rgb), rgb
    views = lines[first + 2].split()
    n = int(views[0])
    assert n >= 2 and len(views) == 1 + 4 * n, views
    for v in range(n):
        c, key = int(views[1 + 4 * v]), int(views[2 + 4 * v])
        x, y = float(views[3 + 4 * v]), float(views[4 + 4 * v])
        f, k1, k2, R, t = cameras[c]
        P = [sum(R[r][k] * X[k] for k in range(3)) + t[r] for r in range(3)]
        assert P[2] < 0, (p, c, P)
        px, py = -P[0] / P[2], -P[1] / P[2]
        r2 = px * px + py * py
        d = 1 + k1 * r2 + k2 * r2 * r2
        errors.append(math.hypot(f * d * px - x, f * d * py - y))
mean = sum(errors) / len(errors)
print("bundler: %d cameras, %d points, %d views, mean reprojection error %.3f px" %
      (num_cameras, num_points, len(errors), mean))
assert mean < 2.0, mean
PY
echo "five third-party plugins, one of each kind, built against the installed SDK ran in one bench row; its Bundler export checks out"
