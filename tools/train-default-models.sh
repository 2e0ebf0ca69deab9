#!/usr/bin/env bash
# Rebuilds the learned models that ship with the project, deterministically: the same
# suite, seeds and settings give the same files byte for byte.
#   crates/polar-material/models/material-knn.bin   (`run --material-model builtin`)
# Usage: tools/train-default-models.sh [WORKDIR]   (renders go to WORKDIR, default
# target/default-models; about 10 CPU-minutes for the 40 samples of 128x128)
set -euo pipefail
cd "$(dirname "$0")/.."
work="${1:-target/default-models}"
cargo build --release -p polar-datagen -p polar-vision
target/release/polar-datagen suite datasets-synth/suites/material-train.toml \
    --out "$work/material-train" --size full --quiet
target/release/polar-vision train material "$work/material-train" --family materials \
    --k 15 --max-points 4000 --seed 1 --out crates/polar-material/models/material-knn.bin
