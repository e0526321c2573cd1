2026-12-06 14:04 UTC
build/bin/tessera bench --images ../shared/datasets/fountain-P11/images --gt ../shared/datasets/fountain-P11/gt --camera-K ../shared/datasets/fountain-P11/K.txt --output /tmp/b49c/fountain-P11 --threads 2 --json /tmp/b49c/fountain-P11.json manifests/calibrated.json manifests/global.json manifests/default.json
