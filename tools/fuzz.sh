#!/usr/bin/env bash
# The cargo-fuzz targets of fuzz/ (hostile input, issue #22); details in fuzz/README.md.
# Needs a nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`).
#   tools/fuzz.sh seed                      seed corpora from a tiny generated dataset
#   tools/fuzz.sh run TARGET [SECONDS]      fuzz one target (default 180 s), nice'd
#   tools/fuzz.sh cmin TARGET               minimize fuzz/corpus/TARGET in place
#   tools/fuzz.sh all [SECONDS]             run, then cmin, every target in turn
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
targets=(png_mosaic exr_stokes sample meta_json manifest scene suite vision_run model_file object_mask)
# No sanitizer: the code under test has no `unsafe`, and without ASan a run does about
# twice the executions. Debug assertions (-a) turn integer overflow into a finding.
build_flags=(--sanitizer none --debug-assertions)
# libFuzzer's own limits behind the harness's allocation bounds: RSS of the whole process,
# and (with a sanitizer build only) any single allocation; -timeout catches hangs.
limits=(-rss_limit_mb=4096 -malloc_limit_mb=4096 -timeout=30 -max_len=262144)
sep=$'\n--POLAR-FUZZ-NEXT-FILE--\n' # harness::PART_SEPARATOR

seed() {
    local data=target/fuzz-seed-dataset
    [ -d "$data" ] || cargo run --release --locked -p polar-datagen -- \
        suite datasets-synth/suites/tiny.toml --out "$data" --jobs 1 >/dev/null
    local c=fuzz/corpus s
    mkdir -p "${targets[@]/#/$c/}"
    for s in "$data"/sfp-00000 "$data"/sfp-00001 "$data"/glass-00000; do
        local n
        n=$(basename "$s")
        cp "$s/raw.png" "$c/png_mosaic/$n-raw.png"
        cp "$s/gt/material.png" "$c/png_mosaic/$n-material.png"
        cp "$s/gt/material.png" "$c/object_mask/$n-material.png"
        cp "$s/stokes.exr" "$c/exr_stokes/$n-stokes.exr"
        cp "$s/gt/depth.exr" "$c/exr_stokes/$n-depth.exr"
        cp "$s/meta.json" "$c/meta_json/$n.json"
        { cat "$s/meta.json"; printf '%s' "$sep"; cat "$s/raw.png"; printf '%s' "$sep"
          cat "$s/stokes.exr"; printf '%s' "$sep"; cat "$s/gt/material.png"
          printf '%s' "$sep"; cat "$s/gt/depth.exr"; } >"$c/sample/$n"
        { cat "$s/meta.json"; printf '%s' "$sep"; cat "$s/raw.png"; printf '%s' "$sep"
          cat "$s/stokes.exr"; } >"$c/vision_run/$n"
        { cat "$s/meta.json"; printf '%s%s' "$sep" "$sep"; cat "$s/stokes.exr"; } \
            >"$c/vision_run/$n-stokes-only"
    done
    head -n 2 "$data/manifest.jsonl" >"$c/manifest/two-lines.jsonl"
    cp datasets-synth/scenes/*.toml "$c/scene/"
    cp datasets-synth/suites/*.toml "$c/suite/"
    cp crates/polar-material/models/material-knn.bin "$c/model_file/builtin.bin"
    head -c 4096 crates/polar-material/models/material-knn.bin >"$c/model_file/truncated.bin"
}

run() {
    local t=$1 secs=${2:-180}
    mkdir -p "fuzz/corpus/$t"
    (cd fuzz && nice cargo +nightly fuzz run "${build_flags[@]}" "$t" "corpus/$t" -- \
        -max_total_time="$secs" "${limits[@]}")
}

cmin() {
    (cd fuzz && nice cargo +nightly fuzz cmin "${build_flags[@]}" "$1" "corpus/$1" -- \
        "${limits[@]}")
}

case "${1:-}" in
    seed) seed ;;
    run) run "$2" "${3:-180}" ;;
    cmin) cmin "$2" ;;
    all) for t in "${targets[@]}"; do run "$t" "${2:-180}"; cmin "$t"; done ;;
    *) sed -n '2,7p' "$0"; exit 2 ;;
esac
