#!/usr/bin/env bash
# Run HERE (Debian bookworm, root): downloads the Debian packages the GPU build needs into
# .deps/debs (git-ignored). The GPU-machine run carries that folder; scripts/gpu/build_and_test.sh
# unpacks it there. PCL's non-I/O libraries + FLANN + LZ4, and the header-only JSON and CLI libs.
set -euo pipefail
cd "$(dirname "$0")/../.."
mkdir -p .deps/debs
cd .deps/debs
apt-get download -qq libpcl-dev libpcl-common1.13 libpcl-kdtree1.13 libpcl-search1.13 \
  libpcl-octree1.13 libpcl-filters1.13 libpcl-sample-consensus1.13 libflann-dev libflann1.9 \
  liblz4-dev liblz4-1 nlohmann-json3-dev libcli11-dev zlib1g-dev zlib1g 2>&1 | grep -v '^W: Download is performed unsandboxed' || true
ls -1 *.deb | wc -l
