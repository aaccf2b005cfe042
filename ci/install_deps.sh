#!/usr/bin/env bash
# Installs the Debian 12 packages irbench needs, and only those missing.
# Idempotent: a second run installs nothing and exits 0. Needs root (or sudo).
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config ninja-build
  libeigen3-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  libopencv-calib3d-dev libopencv-ml-dev libopencv-videoio-dev liblo-dev
  libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libosmesa6-dev
  libopenexr-dev
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libassimp-dev libtinygltf-dev
  liblbfgs-dev  # L-BFGS for the motion-label CRFs (tracker/motion_labels)
  libssl-dev    # SHA-256 of the model files a track used (common/sha256.h)
  gnuplot-nox   # the report's plots (irbench score)
  chromium      # the report's test opens it in headless Chromium
  python3       # ci/checks/code_shape.py (a CTest test): function and file sizes, layering
  clang libclang-rt-14-dev  # ci/sanitize.sh: ASan, UBSan and libFuzzer (fuzz/)
  munge slurmctld slurmd slurm-client  # `irbench sweep submit`: its test starts a one-node Slurm (ci/slurm/)
)

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present" >&2
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install_deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
