#!/usr/bin/env bash
# Installs the Debian bookworm packages sadsplat needs, only those that are missing (idempotent).
# Run as root on a fresh Debian bookworm machine.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libpcl-dev libflann-dev libeigen3-dev libvtk9-dev mpi-default-dev
  libtorch-dev libopencv-dev libgtest-dev libcli11-dev nlohmann-json3-dev zlib1g-dev
  # SPZ version 4 (zstd) and PlayCanvas' SOG (WebP images) in the web splat formats.
  libzstd-dev libwebp-dev
  # Real photos: COLMAP for `sadsplat sfm`, libexif for the photos' GPS (the georeference).
  colmap libexif-dev
  # Map outputs: GDAL writes GeoTIFF / PNG and projects to UTM; gdal-bin's gdalinfo checks them.
  libgdal-dev gdal-bin
  libopen3d-dev python3 python3-open3d
  # gloo's headers: LibTorch's c10d Gloo process group (data-parallel training, --nproc).
  libgloo-dev
  # VTK renders through X only on Debian: headless views, screenshots and report plots run
  # under Xvfb with Mesa's software OpenGL.
  xvfb xauth libgl1-mesa-dri
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "setup: all packages present"
fi
