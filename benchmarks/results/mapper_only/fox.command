2026-12-06 12:29 UTC
build/bin/tessera bench --images ../shared/datasets/fox/images --gt ../shared/datasets/fox/transforms.json --output /tmp/b49/fox --threads 2 --colmap ../shared/anchors/colmap-4/bin/colmap --colmap colmap --colmap-mapper-only --json /tmp/b49/fox.json manifests/global.json manifests/default.json
