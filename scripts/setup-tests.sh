#!/usr/bin/env bash
# What the tests need beyond scripts/setup.sh, on a fresh Debian or Ubuntu machine (run as
# root): Chromium to test the HTML report, Slurm and MUNGE (tests/sweep.rs starts a one-node
# cluster of its own), GNU parallel (the same test runs a sweep's job file through it), Node.js
# with the Khronos glTF validator (into .tools/: tools/tests/export.rs validates every exported
# .glb), and the pinned Python programs of scripts/requirements-tests.txt (NVIDIA's FLIP,
# Mitsuba 3, numpy and OpenEXR) in the checkout's .venv, which the tests find by themselves.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/setup.sh"
need_apt=()
command -v chromium >/dev/null || need_apt+=(chromium)
command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v sbatch >/dev/null || need_apt+=(slurm-wlm)
command -v munged >/dev/null || need_apt+=(munge)
command -v parallel >/dev/null || need_apt+=(parallel)
command -v npm >/dev/null || need_apt+=(nodejs npm)
command -v python3 >/dev/null || need_apt+=(python3)
# Debian's python3 makes virtual environments only with python3-venv (ensurepip).
command -v python3 >/dev/null && python3 -c 'import ensurepip, venv' 2>/dev/null || need_apt+=(python3-venv)
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
# A virtual environment, not the system's Python: Debian refuses a system-wide pip install
# (PEP 668), and the versions are pinned. metrics::python finds .venv/bin/python3.
[ -x "$root/.venv/bin/python3" ] || python3 -m venv "$root/.venv"
"$root/.venv/bin/python3" -m pip install --quiet --disable-pip-version-check -r "$root/scripts/requirements-tests.txt"
# The same probes the tests use.
"$root/.venv/bin/python3" -m flip_evaluator.flip_python_api -h >/dev/null
"$root/.venv/bin/python3" -c 'import mitsuba, numpy, OpenEXR'
# The Khronos glTF validator, pinned, in the checkout's .tools/ (not global): tools/tests/export.rs
# runs it through scripts/gltf-validate.cjs on every exported .glb.
[ -e "$root/.tools/node_modules/gltf-validator/package.json" ] || npm install --silent --no-save --prefix "$root/.tools" gltf-validator@2.0.0-dev.3.10 >/dev/null
node -e "require('$root/.tools/node_modules/gltf-validator')"
