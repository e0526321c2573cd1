#!/bin/bash
# The include rule of check_plugin_includes.sh: first on a small tree made here (it must
# name each bad include, file and line, and accept the good ones), then on the sources.
# usage: plugin_includes_test.sh SOURCE_DIR
set -euo pipefail
source_dir=$1
here=$(dirname "$0")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

mkdir -p "$work/host/include/tessera" "$work/tests/support" "$work/plugins/exporters/common" \
         "$work/plugins/exporters/good" "$work/plugins/detectors/bad"
touch "$work/host/include/tessera/sdk.h" "$work/tests/support/test_support.h" \
      "$work/plugins/exporters/common/paths.h" "$work/plugins/exporters/good/helper.h"
cat > "$work/plugins/exporters/good/good.cc" <<'CC'
#include <vector>
#include "tessera/sdk.h"
#include "common/paths.h"
#include "helper.h"
CC
printf '#include "test_support.h"\n' > "$work/plugins/exporters/good/good_test.cc"
cat > "$work/plugins/detectors/bad/bad.cc" <<'CC'
#include "tessera/sdk.h"
#include "scene/colmap_model_io.h"
#include "tessera/not_there.h"
#include "test_support.h"
#include "../../exporters/good/helper.h"
CC
set +e
output=$(bash "$here/check_plugin_includes.sh" "$work")
status=$?
set -e
expected='plugins/detectors/bad/bad.cc:2: #include "scene/colmap_model_io.h": neither in the SDK (tessera/...) nor local to plugins/detectors/bad or plugins/*/common
plugins/detectors/bad/bad.cc:3: #include "tessera/not_there.h": not a header of the SDK (host/include/tessera/)
plugins/detectors/bad/bad.cc:4: #include "test_support.h": neither in the SDK (tessera/...) nor local to plugins/detectors/bad or plugins/*/common
plugins/detectors/bad/bad.cc:5: #include "../../exporters/good/helper.h": neither in the SDK (tessera/...) nor local to plugins/detectors/bad or plugins/*/common
4 include(s) outside the SDK under '"$work"'/plugins'
[ $status = 1 ] || { echo "FAIL: exit $status on the bad tree, expected 1"; echo "$output"; exit 1; }
[ "$output" = "$expected" ] || { echo "FAIL: got"; echo "$output"; echo "expected"; echo "$expected"; exit 1; }

bash "$here/check_plugin_includes.sh" "$source_dir"
echo "every include under $source_dir/plugins is in the SDK or local to its plugin"
