#!/usr/bin/env bash
# Rebuilds the learned models that ship with the project, deterministically: the same
# suite, seeds and settings give the same files byte for byte.
#   crates/polar-material/models/material-knn.bin         (`run --material-model builtin`)
#   crates/polar-transparency/models/transparent-knn.bin  (`run --transparent-method learned`)
# Usage: tools/train-default-models.sh [WORKDIR]   (renders go to WORKDIR, default
# target/default-models; about 10 CPU-minutes for the 40 material samples of 128x128 and 7
# for the 44 transparent ones)
set -euo pipefail
cd "$(dirname "$0")/.."
work="${1:-target/default-models}"
cargo build --release -p polar-datagen -p polar-vision
target/release/polar-datagen suite datasets-synth/suites/material-train.toml \
    --out "$work/material-train" --size full --quiet
target/release/polar-vision train material "$work/material-train" --family materials \
    --k 15 --max-points 4000 --seed 1 --out crates/polar-material/models/material-knn.bin
target/release/polar-datagen suite datasets-synth/suites/transparent-train.toml \
    --out "$work/transparent-train" --size full --quiet
target/release/polar-vision train transparent "$work/transparent-train" \
    --k 15 --max-points 4000 --seed 1 --out crates/polar-transparency/models/transparent-knn.bin
