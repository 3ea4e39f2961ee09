#!/usr/bin/env bash
# Installs the Debian packages that a group of tasks needs, and touches nothing
# when they are all present, so every other script can call it unconditionally.
#
#   bash tools/install-deps.sh [group...]     (default: base)
#
# Needs root only when something is missing.
set -euo pipefail

declare -A package_groups=(
  [base]="build-essential cmake pkg-config libeigen3-dev libopenblas-dev libcli11-dev nlohmann-json3-dev libfmt-dev liblbfgspp-dev libgtest-dev libgmock-dev libbenchmark-dev python3 universal-ctags libwebsocketpp-dev libasio-dev"
  # The reference implementation the GP trainer is tested and benchmarked against.
  [sklearn]="python3-sklearn python3-numpy"
  # The libFuzzer targets (ctest -L fuzz). clang does not pull in the fuzzer
  # and sanitizer runtimes (libclang-rt-14-dev is only a Recommends); llvm-14
  # brings llvm-symbolizer for readable sanitizer reports.
  [fuzz]="clang libclang-rt-14-dev llvm-14"
  # Real SocketCAN tests (ctest -L socketcan): the host kernel may lack AF_CAN,
  # so they boot a User-Mode Linux kernel that has can, can-raw and vcan as
  # modules, and drive the bus with can-utils; the CAN FD test's client is
  # python-can with the DBC read by canmatrix.
  [uml]="user-mode-linux kmod iproute2 can-utils python3-can python3-canmatrix"
  # The simulated CiA 402 drives (ctest -L canopen): Node.js and npm, and the
  # compiler node-gyp builds the canopen package's one native dependency
  # (node-crc) with; then the package itself from the npm registry, pinned by
  # tools/sim/cia402/package-lock.json.
  [canopen]="nodejs npm make g++"
  # The view's reference clients (ctest -L view, and the demo's check of its
  # recording): Node.js and npm, then the Foxglove WebSocket client, the MCAP
  # reader and Foxglove's schemas from the npm registry, pinned by
  # tools/view/clients/package-lock.json.
  [view]="nodejs npm"
  # The view's screenshot test: a headless browser.
  [browser]="chromium"
  # Cortex-M cross builds and their tests on QEMU's MPS2 boards (ctest -L qemu).
  [cross]="gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib libnewlib-arm-none-eabi binutils-arm-none-eabi qemu-system-arm"
)

log_file=${CDCR_INSTALL_LOG:-/tmp/cdcr-install-deps.log}

die() {
  echo "install-deps: $*" >&2
  exit 1
}

is_installed() {
  [[ $(dpkg-query -W -f='${Status}' "$1" 2>/dev/null || true) == "install ok installed" ]] && return 0
  # Or provided by an installed package (a Node.js build that brings its npm).
  # The list is read whole before it is searched: an early-exiting grep at the
  # end of a pipe would kill the writers with SIGPIPE, which pipefail reports
  # as "not installed" whenever the race goes that way.
  local provided
  provided=$(dpkg-query -W -f='${Status}|${Provides}\n' 2>/dev/null | sed -n 's/^install ok installed|//p' |
    tr ',' '\n' | sed 's/ *(.*//; s/^ *//')
  [[ $'\n'$provided$'\n' == *$'\n'"$1"$'\n'* ]]
}

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

# The npm packages of a group's folder, installed from its lock file (npm
# ci), unless every package of the lock file is there at its version and
# the group's main package loads.
#   install_npm_packages <group> <folder> <package that must load>
install_npm_packages() {
  local group=$1 dir=$2 main=$3
  if node -e "
      const fs = require('fs'), lock = require('$dir/package-lock.json').packages;
      for (const [path, entry] of Object.entries(lock)) {
        if (!path) continue;
        const manifest = '$dir/' + path + '/package.json';
        if (!fs.existsSync(manifest) || require(manifest).version !== entry.version) process.exit(1);
      }
      require('$dir/node_modules/$main');" 2>/dev/null; then
    return 0
  fi
  (cd "$dir" && npm ci --no-audit --no-fund) >>"$log_file" 2>&1 </dev/null || show_log_tail_and_fail "npm ci in $dir"
  echo "install-deps: $group: npm packages installed in $dir (log: $log_file)"
}

# The groups whose npm packages are asked for (npm ci builds the canopen
# stack's node-crc with node-gyp).
install_wanted_npm_packages() {
  [[ " ${groups[*]} " == *" canopen "* ]] && install_npm_packages canopen "$here/sim/cia402" canopen
  [[ " ${groups[*]} " == *" view "* ]] && install_npm_packages view "$here/view/clients" @mcap/core
  return 0
}

show_log_tail_and_fail() {
  echo "install-deps: $1 failed; last lines of $log_file:" >&2
  tail -n 30 "$log_file" >&2
  exit 1
}

groups=("$@")
[[ ${#groups[@]} -gt 0 ]] || groups=(base)

wanted=()
for group in "${groups[@]}"; do
  [[ -n ${package_groups[$group]+set} ]] ||
    die "unknown group '$group' (known: ${!package_groups[*]})"
  read -r -a packages <<<"${package_groups[$group]}"
  wanted+=("${packages[@]}")
done

missing=()
for package in "${wanted[@]}"; do
  if ! is_installed "$package" && [[ " ${missing[*]} " != *" $package "* ]]; then
    missing+=("$package")
  fi
done

wants_npm=false
[[ " ${groups[*]} " == *" canopen "* || " ${groups[*]} " == *" view "* ]] && wants_npm=true

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: ${groups[*]}: all packages present"
  if $wants_npm; then
    : >"$log_file"
    install_wanted_npm_packages
  fi
  exit 0
fi

[[ $(id -u) -eq 0 ]] ||
  die "missing ${missing[*]}; run as root: sudo bash tools/install-deps.sh ${groups[*]}"

: >"$log_file"
export DEBIAN_FRONTEND=noninteractive
apt-get update >>"$log_file" 2>&1 </dev/null || show_log_tail_and_fail "apt-get update"
apt-get install -y --no-install-recommends "${missing[@]}" >>"$log_file" 2>&1 </dev/null ||
  show_log_tail_and_fail "apt-get install"
echo "install-deps: ${groups[*]}: installed ${missing[*]} (log: $log_file)"
$wants_npm && install_wanted_npm_packages
exit 0
