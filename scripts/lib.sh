# Shared by scripts/demo, scripts/test and the other scripts: install what is
# missing, configure and build. Source it; do not run it.
set -euo pipefail

MESHSTREAM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

# Debian packages the build, tests and benchmarks need. The scripts install
# only what is missing, so a machine that has everything is left alone.
MESHSTREAM_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libdraco-dev draco libzstd-dev zstd
  libboost-dev protobuf-compiler libprotobuf-dev
  libcli11-dev nlohmann-json3-dev libexpected-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenmesh-dev libmeshoptimizer-dev
  gnuplot-nox  # bench: the codec rate-distortion plot
  libglfw3-dev libimgui-dev libosmesa6-dev libpng-dev  # viewer: window, panel, off-screen, PNG
  libstb-dev  # stb_image, _resize, _write: texture records (pyramid levels, checks), viewer textures
  xvfb xauth  # viewer tests: a virtual X display for the window
  clang libclang-rt-14-dev  # fuzz targets (libFuzzer) in tests/fuzz
  clang-format  # scripts/check-format, run by scripts/test
  nginx  # tests/http: the HTTP stream path against a real web server
  haproxy curl  # deploy tests: servers behind a real HAProxy; scraping --metrics
  libeigen3-dev  # glTF import: Draco's scene headers (node transforms) use Eigen
)

ms_install_packages() {
  local missing=()
  local pkg
  for pkg in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "installing missing packages: ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null; then sudo="sudo"; else
      echo "error: need root (or sudo) to install: ${missing[*]}" >&2
      exit 1
    fi
  fi
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# ms_build BUILD_DIR [cmake args...]: configure once, then build everything.
ms_build() {
  local dir="$1"
  shift
  if [ ! -f "$dir/build.ninja" ]; then
    cmake -S "$MESHSTREAM_ROOT" -B "$dir" -G Ninja "$@"
  fi
  cmake --build "$dir" -j "$(nproc)"
}

# Where the real test meshes live: $MESHSTREAM_TEST_MESHES or ../shared/meshes.
ms_find_meshes() {
  if [ -n "${MESHSTREAM_TEST_MESHES:-}" ]; then echo "$MESHSTREAM_TEST_MESHES"; return; fi
  local candidate="$MESHSTREAM_ROOT/../shared/meshes"
  if [ -d "$candidate" ]; then (cd "$candidate" && pwd); fi
}

# Node and npm for the glTF validator below (tests only). Debian's nodejs
# and npm unless a node with its own npm is there already (NodeSource's
# nodejs bundles npm and conflicts with Debian's npm package).
ms_install_node() {
  if command -v node >/dev/null && command -v npm >/dev/null; then return 0; fi
  ms_install_packages nodejs npm
}

# The Khronos glTF validator (npm gltf-validator, a JS library) for the glTF
# export tests: installed into DIR/node_modules when missing. Prints DIR/
# node_modules on success; on failure (no npm, registry unreachable) prints
# nothing and says why on stderr, so the tests skip visibly.
MESHSTREAM_GLTF_VALIDATOR_VERSION=2.0.0-dev.3.10
ms_gltf_validator() {
  local dir="$1"
  if [ -f "$dir/node_modules/gltf-validator/package.json" ]; then
    echo "$dir/node_modules"
    return 0
  fi
  if ! command -v npm >/dev/null || ! command -v node >/dev/null; then
    echo "gltf-validator: node/npm not installed (Debian nodejs, npm)" >&2
    return 0
  fi
  mkdir -p "$dir"
  if npm install --no-audit --no-fund --silent --prefix "$dir" \
    "gltf-validator@$MESHSTREAM_GLTF_VALIDATOR_VERSION" >&2; then
    echo "$dir/node_modules"
  else
    echo "gltf-validator: npm install failed (registry unreachable?)" >&2
  fi
}
