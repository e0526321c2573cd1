2026-12-06 14:04 UTC
build/bin/tessera bench --images ../shared/datasets/Herz-Jesus-P8/images --gt ../shared/datasets/Herz-Jesus-P8/gt --camera-K ../shared/datasets/Herz-Jesus-P8/K.txt --output /tmp/b49c/Herz-Jesus-P8 --threads 2 --json /tmp/b49c/Herz-Jesus-P8.json manifests/calibrated.json manifests/global.json manifests/default.json
