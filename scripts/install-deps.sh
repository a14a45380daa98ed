#!/usr/bin/env bash
# Installs the Debian packages coapt builds and runs with (README.md, "Two commands").
# Idempotent: packages already present are not touched and apt is not called at all
# when nothing is missing. Uses sudo when not run as root.
set -euo pipefail

packages=(
  # build and run tools
  cmake g++ make pkg-config openmpi-bin libopenmpi-dev
  # distributed linear algebra and solvers (PETSc 3.18 with hypre, MUMPS, SuperLU_dist, PT-Scotch, HDF5)
  petsc-dev
  # mesh partitioning, mesh input and generation
  libmetis-dev libgmsh-dev
  # small dense algebra, configuration, command line, logging
  libeigen3-dev libyaml-cpp-dev libcli11-dev libfmt-dev libspdlog-dev
  # tests and micro-benchmarks
  libgtest-dev libbenchmark-dev
  # plots and output checks (Debian's Python)
  python3-matplotlib python3-vtk9
)

missing=()
for package in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$package")
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "install-deps: not root and no sudo; install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -q
"${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
