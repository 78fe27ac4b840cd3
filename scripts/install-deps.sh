#!/usr/bin/env bash
# Installs the Debian 12 packages this project needs, only those missing. Idempotent.
set -euo pipefail
packages=(
  build-essential cmake ninja-build git pkg-config clang-format
  libeigen3-dev libsuitesparse-dev zlib1g-dev libopenblas0-pthread
  libprotobuf-dev protobuf-compiler libzmq3-dev cppzmq-dev
  libspdlog-dev libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libgtest-dev
  gmsh libgmsh-dev   # the gmsh CLI (meshing .geo files) and its C++ API (remeshing)
  libpetsc-real-dev openmpi-bin libopenmpi-dev   # the fluid's PETSc engines (petsc, mumps) and MPI ranks (fluid.ranks)
  python3 python3-zmq python3-protobuf python3-yaml python3-matplotlib python3-psutil
  python3-numpy python3-scipy python3-pandas python3-distributed python3-nbformat
  python3-venv python3-setuptools python3-wheel
  python3-meshio python3-vtk9   # read the VTK output back in the tests (tests/python/test_vtk_output.py)
  python3-dolfin   # legacy FEniCS: the example external solid python/examples/fenics_solid
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
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
