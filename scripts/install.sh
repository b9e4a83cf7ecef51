#!/usr/bin/env bash
# One-command install on Debian 12 (root or sudo): system libraries, the CPU build of torch, Cyclone DDS
# 0.10.2 for the G1 backend, and EmoPose itself in editable mode with every extra (piper: GPL-3.0-or-later).
set -euo pipefail
cd "$(dirname "$0")/.."
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive PIP_DISABLE_PIP_VERSION_CHECK=1

$SUDO apt-get update -qq
# espeak-ng: local TTS with word events; chromium: web UI tests; cyclonedds-dev: the G1's DDS (0.10.2);
# EGL/Mesa: offscreen MuJoCo rendering (MUJOCO_GL=egl).
$SUDO apt-get install -y -qq --no-install-recommends \
  espeak-ng libespeak-ng1 chromium chromium-driver cyclonedds-dev cyclonedds-tools \
  libegl1 libegl-mesa0 libgl1-mesa-dri libgbm1 libosmesa6 > /dev/null

python -m pip install -q torch==2.13.0   # the local CPU build; a looser pin pulls GBs of CUDA wheels
bash .ci/install_cyclonedds.sh            # builds cyclonedds==0.10.2 against Debian's C library
# voice: local speech recognition and voice activity (MIT); piper: the neural voice, GPL-3.0-or-later
python -m pip install -q -e ".[embed,web,g1,dev,voice,piper]"
# g1-meshes: Unitree's G1 meshes for the renderers, without holosoma's training stack (pyproject.toml)
G1_MESHES=$(python -c 'import tomllib; print(*tomllib.load(open("pyproject.toml", "rb"))["project"]
  ["optional-dependencies"]["g1-meshes"])')
python -m pip install -q --no-deps $G1_MESHES
echo "EmoPose installed. Try: python -m emopose +experiment=bench_hard"
