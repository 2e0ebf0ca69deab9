#!/usr/bin/env bash
# The main job on the built-in default, offline: render the demo scene with the
# polarized path tracer and the IMX250MZR-like sensor (polar-datagen demo), then
# decode its raw mosaic back into Stokes, DoLP and AoLP (polar-vision stokes),
# and decode a bundled real IMX250MZR frame the same way.
#   usage: tools/demo.sh [OUT_DIR]   (default: out/demo)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out="${1:-out/demo}"

cargo build --release --locked -p polar-datagen -p polar-vision
bin=target/release

"$bin/polar-datagen" demo --out "$out/sample"
"$bin/polar-vision" stokes "$out/sample" --out "$out/vision" --bit-depth 12
"$bin/polar-vision" stokes tests/data/real/camera_IMX250MZR.png --out "$out/real"

cat <<TXT

Done. Look at:
  $out/sample/pictures/{s0,dolp,aolp}.png   rendered (noise-free Stokes)
  $out/vision/{s0,dolp,aolp}.png            decoded from the simulated raw mosaic
  $out/real/{s0,dolp,aolp}.png              decoded from a real IMX250MZR frame
  $out/sample/gt/                           ground truth (normals, depth, labels, mask)
TXT
