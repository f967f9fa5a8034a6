#!/usr/bin/env bash
# Installs the Debian 12 packages pliant needs, skipping what is already installed.
# Usage: bash tools/setup-debian.sh            (as root, or with sudo available)
set -euo pipefail

packages=(
  cmake g++ make pkg-config      # build
  ninja-build ccache             # tools/test.sh: Ninja builds, every compile cached
  dpkg-dev                       # tools/packages.sh: dpkg-shlibdeps reads the program's run-time Depends
  clang-format clang-tidy        # tools/lint.sh
  python3                        # tools/lint_tidy.py
  python3-dev                    # the Python module (host/python): Python's headers
  pybind11-dev                   # the Python module: C++ bindings
  python3-numpy                  # the Python module: recordings as NumPy arrays (also tools/concealed/)
  python3-pytest                 # the Python module's and the fleet's tests (tests/python, tests/fleet)
  python3-distributed            # pliant batch: the fleet on Dask distributed (host/python/pliant/fleet.py)
  python3-tqdm                   # the fleet's progress bar
  libeigen3-dev                  # core linear algebra (the only core dependency)
  nlohmann-json3-dev             # recording and result JSON (host)
  libcli11-dev                   # the pliant command line
  libtet1.5-dev                  # TetGen: tetrahedralize closed surfaces (host FEM)
  libspectra-dev                 # sparse eigenvalues: FEM modal analysis and warm starts
  libceres-dev                   # Levenberg-Marquardt material estimation (host FEM)
  libgtest-dev                   # unit tests
  libbenchmark-dev               # bench/
  clang libclang-rt-14-dev       # libFuzzer targets and their sanitizer runtimes
  chromium                       # headless browser for the report rendering test
  libopencv-dev                  # vision front end (dense optical flow) and the opencv driver
  libnanoflann-dev               # kd-tree for the depth tracker's correspondences
  libpng-dev                     # 16-bit depth PNGs (the depth front end decodes them with libpng)
  libmodbus-dev                  # modbus driver: Robotiq grippers and FT 300, and its test emulator
  libusb-1.0-0-dev               # usb driver: device discovery and hotplug
  libopenni2-dev                 # openni2 driver: depth cameras and .oni playback
  libcamera-dev                  # libcamera driver: cameras on embedded Linux
  g++-aarch64-linux-gnu qemu-user  # cross build for aarch64 Linux, its tests run under qemu-aarch64
  googletest file                # GoogleTest sources, compiled for aarch64; `file` checks the binaries
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib  # Cortex-M firmware
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi
as_root=()
if [ "$(id -u)" -ne 0 ]; then as_root=(sudo); fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
