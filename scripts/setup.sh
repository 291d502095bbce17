#!/usr/bin/env bash
# Installs what flicker needs on a fresh Debian machine without a GPU (run as root):
# Mesa's lavapipe (CPU Vulkan) for wgpu, Chromium to test the HTML report, Slurm and MUNGE
# (tests/sweep.rs starts a one-node cluster of its own), GNU parallel (the same test runs a
# sweep's job file through it), Node.js with the Khronos glTF validator (npm `gltf-validator`,
# into .tools/node_modules: tools/tests/export.rs validates every exported .glb), and NVIDIA's FLIP reference
# implementation (PyPI `flip-evaluator`) that the FLIP tests compare against.
set -euo pipefail
need_apt=()
[ -e /usr/share/vulkan/icd.d/lvp_icd.x86_64.json ] || [ -e /usr/share/vulkan/icd.d/lvp_icd.json ] || need_apt+=(mesa-vulkan-drivers)
ldconfig -p | grep -q 'libvulkan.so.1' || need_apt+=(libvulkan1)
command -v chromium >/dev/null || need_apt+=(chromium)
command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v sbatch >/dev/null || need_apt+=(slurm-wlm)
command -v munged >/dev/null || need_apt+=(munge)
command -v parallel >/dev/null || need_apt+=(parallel)
command -v npm >/dev/null || need_apt+=(nodejs npm)
if [ ${#need_apt[@]} -gt 0 ]; then
    export DEBIAN_FRONTEND=noninteractive
    # The packages' own services (munge, slurmctld, slurmd) must not start: the sweep test runs
    # its daemons with its own configuration. policy-rc.d 101 = "action forbidden".
    own_policy=0
    if [ ! -e /usr/sbin/policy-rc.d ]; then
        printf '#!/bin/sh\nexit 101\n' > /usr/sbin/policy-rc.d && chmod +x /usr/sbin/policy-rc.d && own_policy=1
    fi
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${need_apt[@]}" >/dev/null
    if [ $own_policy = 1 ]; then rm -f /usr/sbin/policy-rc.d; fi
fi
# The same probe the FLIP tests use (metrics::reference_flip::reference_flip_available).
python3 -m flip_evaluator.flip_python_api -h >/dev/null 2>&1 || python3 -m pip install --quiet flip-evaluator
python3 -m flip_evaluator.flip_python_api -h >/dev/null
# Mitsuba 3's scalar CPU path tracer: the independent renderer of systems/tests/mitsuba_agreement.rs and
# the reference that `flicker bench` measures the WGSL path tracer against.
python3 -c "import mitsuba" 2>/dev/null || python3 -m pip install --quiet mitsuba==3.9.1
python3 -c "import mitsuba"
# numpy and the OpenEXR bindings, pinned: the walk-through's outside method (scripts/accumulate.py,
# run by tests/walkthrough.rs) reads and writes the exported EXRs with them.
python3 -c "import numpy, OpenEXR" 2>/dev/null || python3 -m pip install --quiet OpenEXR==3.5.3 numpy==2.4.6
python3 -c "import numpy, OpenEXR"
# The Khronos glTF validator, pinned, in the checkout's .tools/ (not global): tools/tests/export.rs
# runs it through scripts/gltf-validate.cjs on every exported .glb.
root="$(cd "$(dirname "$0")/.." && pwd)"
[ -e "$root/.tools/node_modules/gltf-validator/package.json" ] || npm install --silent --no-save --prefix "$root/.tools" gltf-validator@2.0.0-dev.3.10 >/dev/null
node -e "require('$root/.tools/node_modules/gltf-validator')"
