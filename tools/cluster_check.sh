#!/usr/bin/env bash
# Runs the Slurm array scripts of tools/slurm as their array tasks would (each shard's
# SLURM_ARRAY_TASK_ID set by hand) on the tiny suite, then the merges their headers
# describe, so that the job files stay runnable as the CLIs change. Needs the release
# binaries (cargo build --release).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
bin="$PWD/target/release"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
for k in 1 2; do
    SLURM_ARRAY_TASK_ID=$k SHARDS=2 SUITE=datasets-synth/suites/tiny.toml OUT="$tmp/data" \
        SIZE=ci POLAR_DATAGEN="$bin/polar-datagen" bash tools/slurm/datagen-array.sbatch &>/dev/null
done
"$bin/polar-datagen" merge "$tmp"/data/shard-* --out "$tmp/data/merged" >/dev/null
for k in 1 2; do
    SLURM_ARRAY_TASK_ID=$k SHARDS=2 DATASET="$tmp/data/merged" OUT="$tmp/eval" \
        EVAL_ARGS="--tasks sfp --jobs 2" POLAR_VISION="$bin/polar-vision" \
        bash tools/slurm/eval-array.sbatch >/dev/null
done
# eval-merge fails unless the two shards hold every sample of the dataset.
"$bin/polar-vision" eval-merge "$tmp"/eval/shard-* --out "$tmp/eval/merged" >/dev/null
samples=$(find "$tmp/data/merged" -mindepth 1 -maxdepth 1 -type d | wc -l)
echo "datagen and eval array scripts: 2 shards each, merged; $samples samples evaluated"
