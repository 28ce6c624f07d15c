#!/usr/bin/env bash
# Run ON THE GPU MACHINE (Ubuntu 24.04, LibTorch 2.11 + CUDA 13, no PCL/OpenCV/VTK) from the
# repository root, with .deps/debs copied along (scripts/gpu/fetch_deps.sh makes it here):
#   bash scripts/gpu/build.sh
# Builds the CUDA-enabled project without OpenCV/VTK into build-gpu/. Logs go to
# $OUT (when set) so that they can be collected from one folder.
set -euo pipefail
out="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$out"
prefix=/tmp/sadsplat-deps
# Unpacked once per set of packages (two builds on one machine share it).
stamp=$(ls -l .deps/debs/ | md5sum | cut -d' ' -f1)
if [ "$(cat "$prefix/.unpacked" 2>/dev/null)" != "$stamp" ]; then
  rm -rf "$prefix" && mkdir -p "$prefix"
  for deb in .deps/debs/*.deb; do dpkg -x "$deb" "$prefix"; done
  echo "$stamp" > "$prefix/.unpacked"
fi
export LD_LIBRARY_PATH="$prefix/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"

torch_cmake=/opt/torch/.venv/lib/python3.12/site-packages/torch/share/cmake
if [ ! -d "$torch_cmake" ]; then
  torch_cmake=$(python3 -c 'import torch; print(torch.utils.cmake_prefix_path)')
fi
export PATH=/usr/local/cuda/bin:$PATH
generator=(-G "Unix Makefiles")
command -v ninja >/dev/null && generator=(-G Ninja)

{
  echo "== machine"; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv || true
  nvcc --version | tail -2; g++ --version | head -1; cmake --version | head -1
} 2>&1 | tee "$out/gpu_env.log"

# zlib (.spz): the machine's own when it has the headers, else the unpacked Debian package.
zlib_args=()
[ -f /usr/include/zlib.h ] || zlib_args=(-DZLIB_ROOT="$prefix/usr")

start=$(date +%s)
cmake -S . -B build-gpu "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$torch_cmake" \
  -DSADSPLAT_PCL_ROOT="$prefix" \
  -Dnlohmann_json_DIR="$prefix/usr/share/cmake/nlohmann_json" \
  -DCLI11_DIR="$prefix/usr/share/cmake/CLI11" \
  -DSADSPLAT_WITH_CUDA=ON -DSADSPLAT_WITH_OPENCV=OFF -DSADSPLAT_WITH_VTK=OFF \
  -DSADSPLAT_WITH_OPEN3D=OFF "${zlib_args[@]}" \
  2>&1 | tee "$out/gpu_configure.log"
cmake --build build-gpu -j "$(nproc)" 2>&1 | tee "$out/gpu_build.log"
echo "build seconds: $(( $(date +%s) - start ))" | tee -a "$out/gpu_build.log"
