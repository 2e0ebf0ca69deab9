#!/usr/bin/env bash
# Creates (or updates) tools/.venv from tools/requirements.txt and installs the
# system library Mitsuba's LLVM variants need (Debian's libllvm19). Idempotent:
# safe to run again; does nothing that is already done. Usable on a fresh CI
# machine (needs python3 with venv, and root or sudo for apt-get).
#
# Use the venv with:  export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
# (tools/mitsuba/*.py set it themselves).
set -euo pipefail

tools_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$tools_dir/.venv"
requirements="$tools_dir/requirements.txt"

as_root() {
    if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

if ! dpkg-query -W -f='${Status}' libllvm19 2>/dev/null | grep -q "install ok installed"; then
    echo "setup-venv: installing libllvm19 (Mitsuba's LLVM backend)"
    as_root apt-get update -qq
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libllvm19 >/dev/null
fi

if [ ! -x "$venv/bin/python" ]; then
    echo "setup-venv: creating $venv"
    python3 -m venv "$venv"
fi

# pip skips what is already installed at the pinned version.
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$requirements"
echo "setup-venv: $venv ready"
