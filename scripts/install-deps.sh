#!/usr/bin/env bash
# Installs what the project needs from Debian 12's packages, and only what is
# missing. Idempotent; run as root (or with sudo available).
set -euo pipefail

packages=(
  # build
  cmake g++ make git pkg-config
  # numerics: Eigen, CHOLMOD on OpenBLAS (the Debian alternatives pick OpenBLAS
  # over the 4-8x slower reference BLAS once it is installed)
  libeigen3-dev libsuitesparse-dev libopenblas-dev
  # output, scene files, command line, logging, tests
  libhdf5-dev libtomlplusplus-dev libcli11-dev libspdlog-dev libfmt-dev catch2
  # checkpoints' checksums (CRC-32)
  zlib1g-dev
  # figures, and ParaView's Python for checking that our output opens
  python3 python3-matplotlib python3-numpy python3-h5py python3-paraview
  # scene files edited by the studies (comments kept); the outburst's finer
  # seepage mesh, meshed from seam.geo by its sensitivity study
  python3-tomlkit gmsh
  # the ensembles' confidence intervals (Student t); the scenes' units read
  # in Python (cases/units.py); the Python tests (tests/python)
  python3-scipy python3-pint python3-pytest
  # the manual (docs/, mkdocs.yml): MkDocs and its Material theme, which brings
  # the pymdownx extensions mkdocs.yml names; CTest builds it with --strict
  mkdocs mkdocs-material
  # the main job's film (cases/outburst/animate.py): matplotlib writes H.264
  # through ffmpeg, and a GIF through Pillow where no encoder is installed
  ffmpeg python3-pil
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
