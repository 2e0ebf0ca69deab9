#!/usr/bin/env bash
# The main job on the built-in default, offline: render the demo scene with the
# polarized path tracer and the IMX250MZR-like sensor (polar-datagen demo), then
# decode its raw mosaic back into Stokes, DoLP and AoLP (polar-vision stokes),
# and decode a bundled real IMX250MZR frame the same way; then run the analysis tasks
# (polar-vision run: shape, transparency, material, dehazing) on both.
#   usage: tools/demo.sh [OUT_DIR]   (default: out/demo)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out="${1:-out/demo}"

cargo build --release --locked -p polar-datagen -p polar-vision
bin=target/release

"$bin/polar-datagen" demo --out "$out/sample"
"$bin/polar-vision" stokes "$out/sample" --out "$out/vision" --bit-depth 12
"$bin/polar-vision" stokes tests/data/real/camera_IMX250MZR.png --out "$out/real"
# Exit code 2 means a task could not run on the input (it says why); the others ran.
"$bin/polar-vision" run "$out/sample" --out "$out/tasks" --bit-depth 12 || [ $? -eq 2 ]
"$bin/polar-vision" run tests/data/real/camera_IMX250MZR.png --out "$out/real-tasks" \
    --tasks sfp,transparent,material || [ $? -eq 2 ]

cat <<TXT

Done. Look at:
  $out/sample/pictures/{s0,dolp,aolp}.png   rendered (noise-free Stokes)
  $out/vision/{s0,dolp,aolp}.png            decoded from the simulated raw mosaic
  $out/real/{s0,dolp,aolp}.png              decoded from a real IMX250MZR frame
  $out/sample/gt/                           ground truth (normals, depth, labels, mask)
  $out/tasks/pictures/                      the tasks on the simulated frame (metrics.json: scores)
  $out/real-tasks/pictures/                 the tasks on the real frame
TXT
