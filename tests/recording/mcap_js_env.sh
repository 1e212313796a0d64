# Sourced by the rosbag2 interop scripts (check_ros2_interop.sh, check_ros2_recordings.sh): with $here (this
# folder) and $out set, skips (exit 77) without node or npm, makes $out/work afresh, installs mcap_js/'s locked
# packages into $out/npm (npm ci, again only when the lock changed; skip when it fails, e.g. offline), exports
# NODE_PATH, and defines w (the work folder), failures, fail and ok.
command -v node >/dev/null || { echo "SKIP: node is not installed"; exit 77; }
command -v npm >/dev/null || { echo "SKIP: npm is not installed"; exit 77; }
mkdir -p "$out" && rm -rf "$out"/work && mkdir -p "$out/work" "$out/npm"
if ! cmp -s "$here/mcap_js/package-lock.json" "$out/npm/package-lock.json" || [[ ! -d $out/npm/node_modules ]]; then
  cp "$here/mcap_js/package.json" "$here/mcap_js/package-lock.json" "$out/npm/"
  (cd "$out/npm" && npm ci --no-audit --no-fund >npm.log 2>&1) || { echo "SKIP: npm ci failed (offline?): $(tail -3 "$out/npm/npm.log")"; rm -f "$out/npm/package-lock.json"; exit 77; }
fi
export NODE_PATH=$out/npm/node_modules
w=$out/work failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }
