#!/usr/bin/env bash
# The installed package as a user meets it: `cmake --install` into a fresh prefix, the Debian
# package from `cpack -G DEB` unpacked into another, and examples/building_footprints configured
# with find_package(sadsplat) against each, built, and run on a small trained model.
#   install_and_example.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
# The example uses PCL's own CMake package (segmentation, features): a machine without it (a bare
# CUDA machine with an unpacked PCL) skips this test (ctest's skip code 77).
pcl_config=""
for f in /usr/lib/*/cmake/pcl/PCLConfig.cmake /usr/local/share/pcl*/PCLConfig.cmake \
         /usr/share/pcl*/PCLConfig.cmake; do
  [ -f "$f" ] && pcl_config=$f
done
if [ -z "$pcl_config" ]; then
  echo "no PCLConfig.cmake here: skipped"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)

cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
test -x "$tmp/prefix/bin/sadsplat"
test -f "$tmp/prefix/lib/cmake/sadsplat/sadsplatConfig.cmake"
test -f "$tmp/prefix/lib/cmake/sadsplat/sadsplatConfigVersion.cmake"
test -f "$tmp/prefix/include/sadsplat/filters/class_extraction.h"
test -f "$tmp/prefix/include/sadsplat/semantic_drop/class_extraction.h"  # the forwarding header

"$tmp/prefix/bin/sadsplat" train "$src/data/tiny_scene.cache" --iterations 60 --out "$tmp/run" >/dev/null

run_example() {  # PREFIX NAME
  cmake -S "$src/examples/building_footprints" -B "$tmp/ex_$2" "${generator[@]}" \
    -DCMAKE_PREFIX_PATH="$1" >"$tmp/configure_$2.log" 2>&1 || { cat "$tmp/configure_$2.log"; exit 1; }
  cmake --build "$tmp/ex_$2" >"$tmp/build_$2.log" 2>&1 || { cat "$tmp/build_$2.log"; exit 1; }
  # The example extracts a class through the torch-free filters layer: no LibTorch is linked.
  if ldd "$tmp/ex_$2/building_footprints" | grep -i -e torch -e libc10; then
    echo "building_footprints links LibTorch"; exit 1
  fi
  "$tmp/ex_$2/building_footprints" "$tmp/run/model.ply" "$tmp/run/classes.json" building \
    "$tmp/objects_$2" 0.5 5
  # At least one object; its PCD holds as many Gaussians as the table says.
  rows=$(($(wc -l <"$tmp/objects_$2/objects.csv") - 1))
  [ "$rows" -ge 1 ] || { echo "no objects found"; exit 1; }
  # The automatic tolerance (4 x the median spacing, 1 to 3 m) says what it chose.
  "$tmp/ex_$2/building_footprints" "$tmp/run/model.ply" "$tmp/run/classes.json" building \
    "$tmp/objects_auto_$2" | tee "$tmp/auto_$2.log"
  grep -q "^cluster tolerance " "$tmp/auto_$2.log" || { echo "no automatic tolerance"; exit 1; }
  if "$tmp/ex_$2/building_footprints" "$tmp/run/model.ply" "$tmp/run/classes.json" building \
    "$tmp/objects_bad_$2" 1x 2>/dev/null; then echo "a bad tolerance was accepted"; exit 1; fi
  want=$(sed -n 2p "$tmp/objects_$2/objects.csv" | cut -d, -f2)
  # Built with Open3D: the ground plane's height column is there.
  if grep -q "sadsplat_WITH_OPEN3D ON" "$1/lib/cmake/sadsplat/sadsplatConfig.cmake"; then
    head -1 "$tmp/objects_$2/objects.csv" | grep -q ",height_m$" || { echo "no height_m column"; exit 1; }
  fi
  "$tmp/prefix/bin/sadsplat" info "$tmp/objects_$2/object_000.pcd" | grep -qx "gaussians: $want" \
    || { echo "object_000.pcd does not hold $want Gaussians"; exit 1; }
}
run_example "$tmp/prefix" install

# The Debian package: its metadata, and the same example against its unpacked files.
command -v dpkg-deb >/dev/null || { echo "install + example: ok; no dpkg-deb here: .deb not checked"; exit 0; }
(cd "$build" && cpack -G DEB -B "$tmp/deb" >"$tmp/cpack.log" 2>&1) || { cat "$tmp/cpack.log"; exit 1; }
deb=$(ls "$tmp"/deb/sadsplat_*.deb)
dpkg-deb --field "$deb" Package Version Depends
dpkg-deb --field "$deb" Depends | grep -q libtorch-dev
dpkg-deb -x "$deb" "$tmp/debroot"
test -x "$tmp/debroot/usr/bin/sadsplat"
run_example "$tmp/debroot/usr" deb
echo "install + example + deb: ok"
