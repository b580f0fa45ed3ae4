#!/bin/sh
# Install every Debian 12 package the project needs (as root or via sudo).
# Safe to rerun: when everything is present it returns in about a second.
set -eu
PKGS="build-essential cmake pkg-config git
  liggghts libliggghts-dev
  openfoam
  openmpi-bin libopenmpi-dev
  libvtk9-dev libhdf5-dev libeigen3-dev
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libfmt-dev libgtest-dev
  slurm-wlm munge
  python3 python3-matplotlib python3-numpy python3-h5py python3-pil
  chromium"
# --no-install-recommends: openfoam recommends ParaView, whose python3-paraview
# conflicts with python3-vtk9 (needed by libvtk9-dev); see docs/install.md.
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -z "$missing" ]; then
  echo "install-deps: all packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing:$missing"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends $missing
