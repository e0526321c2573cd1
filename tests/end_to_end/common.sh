# Shared by the end-to-end scripts (sourced): failing, the dataset check and the scores
# of a model by `tessera eval`.

fail() {
  echo "FAIL: $*"
  exit 1
}

# Exits with 77 (CTest's skip) when DATASET has no images folder.
require_dataset() {
  if [ ! -d "$1/images" ]; then
    echo "SKIP: $1 not found"
    exit 77
  fi
}

# TESSERA MODEL GT: prints "registered pos_mean_rel mean_reprojection_error_px".
model_scores() {
  "$1" eval "$2" "$3" --json | python3 -c '
import json, sys
e = json.load(sys.stdin)
print(e["registered"], e["pos_mean_rel"], e["mean_reprojection_error_px"])'
}
