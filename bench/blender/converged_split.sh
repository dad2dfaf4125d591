#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# ao's converged maps (1024 rays per texel, --texel-sampling area and centre, seeds 99 and 7)
# against Cycles' (1024 samples, seeds 0 and 1), split by kind of texel (converged_split.py).
#   bench/blender/converged_split.sh [MESH.obj] [SIZE] [OUT_DIR]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
ao="${AO:-$here/../../build/src/ao}"
mesh="${1:-$here/../../../shared/data/meshes/refined_elephant_uv.obj}"
size="${2:-512}"
out="${3:-$(mktemp -d)}"
for seed in 99 7; do
  for sampling in area centre; do
    [ -f "$out/ao-$sampling-$seed.exr" ] || "$ao" --threads 2 bake "$mesh" -s "$size" --samples 1024 --seed "$seed" --padding 0 --denoise 0 \
      --texel-sampling "$sampling" -o "$out/ao-$sampling-$seed.exr" >&2
  done
done
for seed in 0 1; do
  [ -f "$out/cyc-$seed.exr" ] || CYCLES_SEED=$seed blender -b --factory-startup --python "$here/bake_ao.py" -- "$mesh" "$size" 1024 "$out/cyc-$seed.exr" 2 >/dev/null 2>&1
done
blender -b --factory-startup --python "$here/converged_split.py" -- "$mesh" "$out" 2>/dev/null | grep -E '^(noise|texels|all|overlapping|chart|interior)'
