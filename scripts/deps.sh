#!/usr/bin/env bash
# Installs the Debian packages pyrseg needs to build and test, only those missing (apt-get; root or sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config  # toolchain
  libgtest-dev libbenchmark-dev                 # tests, benchmarks
  liblzf-dev libpng-dev                         # PCD binary_compressed, PNG pictures and depth images
  libtiff-dev                                   # float TIFF depth images
  libtinyxml2-dev libyaml-dev                   # calibration files (OpenCV's FileStorage layout; JSON: nlohmann)
  libpcl-dev                                    # PLY clouds via PCL's io (the peer benchmarks use PCL too)
  libopencv-dev nlohmann-json3-dev              # peer benchmarks (connectedComponents); statistics as JSON
  libhwy-dev                                    # Google Highway: the CPU backend's vector passes
  libtbb-dev                                    # oneTBB: the CPU backend's threads
  clang clang-format glslang-tools spirv-tools  # shaders/ compile checks as OpenCL C and GLSL; style
  ocl-icd-opencl-dev opencl-headers pocl-opencl-icd  # the OpenCL backend, and PoCL to run it on in CI
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers  # the Vulkan backend, lavapipe, the validation layer
  doxygen                                       # the API reference (scripts/api-docs.sh)
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest  # the Python module and its tests
  python3-setuptools python3-wheel python3-venv python3-pip  # pip install --no-build-isolation . (offline)
  python3-opencv python3-open3d                 # the Python examples (examples/python)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi
echo "pyrseg: installing missing Debian packages: ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "pyrseg: need root or sudo to install ${missing[*]}" >&2; exit 1; }
  sudo=sudo
fi
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
