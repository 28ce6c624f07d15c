# Sourced, never run: loaders.gl's LAS reader (laz-rs) installed once into $tools
# (.deps/splat-tools, git-ignored) with read_las_with_loadersgl.mjs beside it, for
# las_check.sh and object_las_check.sh. Needs $root (the repository) and $tools set.
# Pinned to one release line: @loaders.gl/las 4.5.1 asks for core ~4.4.0 (npm ERESOLVE with 4.5.1).
if [ ! -d "$tools/node_modules/@loaders.gl/las" ]; then
  mkdir -p "$tools"
  (cd "$tools" && { [ -f package.json ] || npm init -y >/dev/null; } &&
     npm install --no-audit --no-fund @loaders.gl/core@4.4.5 @loaders.gl/las@4.4.5 >/dev/null)
fi
cp "$root/scripts/interop/read_las_with_loadersgl.mjs" "$tools/"
