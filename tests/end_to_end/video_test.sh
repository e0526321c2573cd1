#!/bin/bash
# Video input end to end: a video made here from the 50 ordered fox frames at 360 px
# wide (H.264 MP4, OpenCV's VideoWriter), with a blurred copy after every third frame and
# the camera held still for 8 frames twice (tessera_test_video). `tessera run --video` with
# the default manifest for video (ordered_loop.json) must keep no blurred frame, leave no
# gap of more than two segments' motion (plus one frame's) along the path, from its start
# to its end, and register every kept frame in one model. Bad input: a missing and an empty video are exit 2 naming the file.
# usage: video_test.sh TESSERA MAKE_VIDEO SHARED_DIR
set -uo pipefail
tessera=$1
make_video=$2
shared=${TESSERA_SHARED_DIR:-$3}
dataset="$shared/datasets/fox"
source "$(dirname "$0")/common.sh"
require_dataset "$dataset"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$make_video" "$dataset/images" "$work/fox.mp4" 360 avc1 10 8 > "$work/truth.txt" ||
  fail "cannot write an H.264 MP4 test video"
"$tessera" run --video "$work/fox.mp4" --output "$work/out" --threads 2 > "$work/run.log" 2>&1 ||
  { tail -30 "$work/run.log"; fail "tessera run --video"; }
grep -q "frames/s decoded, selection" "$work/run.log" || { cat "$work/run.log"; fail "no video log line"; }
python3 - "$work/truth.txt" "$work/out/frames.json" "$work/out/mapping_summary.json" <<'PY' ||
import json, sys
truth = {}
for line in open(sys.argv[1]):
    index, source, kind = line.split()
    truth[int(index)] = (int(source), kind)
video = json.load(open(sys.argv[2]))["videos"][0]
assert video["num_frames"] == len(truth), (video["num_frames"], len(truth))
kept = [f for f in video["frames"] if f["selected"]]
blurred = [f["index"] for f in kept if truth[f["index"]][1] == "blurred"]
assert not blurred, f"blurred frames kept: {blurred}"
sources = [truth[f["index"]][0] for f in kept]
num_sources = max(s for s, _ in truth.values()) + 1
# N from the motion: between two kept frames at most two segments' motion (plus one
# frame's), which is N source frames where the path is slowest.
motion = [f["motion_px"] for f in video["frames"]]
segment = video["total_motion_px"] / video["num_segments"]
bound = 2 * segment + max(motion)
ends = [0] + [f["index"] for f in kept] + [len(motion) - 1]
for a, b in zip(ends, ends[1:]):
    moved = sum(motion[a + 1:b + 1])
    assert moved <= bound, f"{moved:.0f} px of motion between frames {a} and {b} > {bound:.0f}"
gaps = [b - a for a, b in zip(sources, sources[1:])]
mapping = json.load(open(sys.argv[3]))
models = mapping["models"]
assert len(models) == 1, f"{len(models)} models"
assert models[0]["num_images"] == len(kept), f'{models[0]["num_images"]} of {len(kept)} registered'
print(f"{video['num_frames']} frames, {len(kept)} kept in {video['num_segments']} segments, "
      f"none blurred, at most {bound:.0f} px of motion (largest gap {max(gaps)} source "
      f"frames) between kept frames, all {len(kept)} registered in one model")
PY
  fail "video selection or reconstruction"

"$tessera" run --video "$work/missing.mp4" --output "$work/out2" > "$work/missing.log" 2>&1
code=$?
[ "$code" = 2 ] || fail "missing video: exit $code, expected 2"
grep -q "$work/missing.mp4: no such video file" "$work/missing.log" || { cat "$work/missing.log"; fail "missing video: message"; }
: > "$work/empty.mp4"
"$tessera" run --video "$work/empty.mp4" --output "$work/out3" > "$work/empty.log" 2>&1
code=$?
[ "$code" = 2 ] || fail "empty video: exit $code, expected 2"
grep -q "$work/empty.mp4: " "$work/empty.log" || { cat "$work/empty.log"; fail "empty video: message"; }
echo "PASS: missing and empty videos are exit 2 naming the file"
