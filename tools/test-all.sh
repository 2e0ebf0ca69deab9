#!/usr/bin/env bash
# The whole test suite, as CI runs it (see README "Set-up"):
#   1. the pinned Python references (tools/.venv) and Debian's libllvm19 for Mitsuba,
#   2. formatting and lints,
#   3. every Rust test in release mode (numeric-heavy),
#   4. the cross-checks that regenerate reference outputs with the pinned Python
#      packages and compare them with ours (drift in either side fails the run).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

step() { printf '\n==== %s ====\n' "$*"; }

step "Python references (pinned venv)"
tools/setup-venv.sh

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy -D warnings"
cargo clippy --workspace --all-targets --locked -- -D warnings

step "cargo test --release"
cargo test --workspace --release --locked

py=tools/.venv/bin/python
step "image primitives vs opencv-contrib / scikit-image"
"$py" tools/imgproc_goldens.py --check

step "task metrics vs numpy / scikit-image"
"$py" tools/eval_goldens.py --check

step "dark-channel dehazing vs OpenCV (regenerated goldens equal the committed ones)"
tmp="$(mktemp -d)"
"$py" tools/dehaze_dcp_reference.py "$tmp/s0.bin" --synthetic 64 48 --width 64 --height 48 \
    --out-t "$tmp/t.bin" --out-radiance "$tmp/radiance.bin"
golden=crates/polar-dehaze/tests/golden
cmp "$golden/dcp_s0.bin" "$tmp/s0.bin"
cmp "$golden/dcp_t.bin" "$tmp/t.bin"
cmp "$golden/dcp_radiance.bin" "$tmp/radiance.bin"
rm -rf "$tmp"

step "front end vs polanalyser"
"$py" tools/polanalyser_goldens.py --check

step "Mitsuba 3: Stokes frame experiment"
"$py" tools/mitsuba/polarizer_check.py --threads 2

step "Mitsuba 3: polarized Rayleigh phase function in volpath"
"$py" tools/mitsuba/rayleigh_check.py --threads 2

step "Mie scattering vs miepython"
"$py" tools/mie_check.py

step "BSDF Mueller matrices vs Mitsuba 3"
"$py" tools/bsdf_crosscheck.py

step "simulator vs Mitsuba 3 (four converged surface scenes and haze)"
"$py" tools/mitsuba/crosscheck.py out/crosscheck --threads 2
