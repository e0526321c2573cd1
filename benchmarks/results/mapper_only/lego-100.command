2026-12-06 12:25 UTC
build/bin/tessera bench --images ../shared/datasets/lego-100/images --gt ../shared/datasets/lego-100/transforms.json --output /tmp/b49/lego-100 --threads 2 --colmap ../shared/anchors/colmap-4/bin/colmap --colmap colmap --colmap-mapper-only --json /tmp/b49/lego-100.json manifests/large_unordered_global.json manifests/large_unordered.json
