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
