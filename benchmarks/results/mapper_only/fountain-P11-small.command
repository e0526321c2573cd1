2026-12-06 04:38 UTC
build/bin/tessera bench --images examples/fountain-P11-small/images --gt ../shared/datasets/fountain-P11/gt --output /tmp/t-bench/b1 --threads 2 --colmap ../shared/anchors/colmap-4/bin/colmap --colmap colmap --colmap-mapper-only --json /tmp/t-bench/b1.json manifests/global.json
