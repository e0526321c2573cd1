2026-12-06 04:51 UTC
build/bin/tessera bench --images ../shared/datasets/fountain-P11/images --gt ../shared/datasets/fountain-P11/gt --output /tmp/t-bench/bench-fountain-P11 --json /tmp/t-bench/bench-fountain-P11.json --with-colmap manifests/default.json manifests/global.json
