2026-12-06 04:51 UTC
build/bin/tessera bench --images ../shared/datasets/Herz-Jesus-P8/images --gt ../shared/datasets/Herz-Jesus-P8/gt --output /tmp/t-bench/bench-Herz-Jesus-P8 --json /tmp/t-bench/bench-Herz-Jesus-P8.json --with-colmap manifests/default.json manifests/global.json
