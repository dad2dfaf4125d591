#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Prints a SHA-256 digest of every output of a fixed set of `ao render` and `ao bake` runs: the
# ray-traced passes (reference of each membership, tangent sphere, transfer, adaptive sampling, the
# sun pass, the G-buffer) on every built-in scene, and the bakes (map filtered and not, intersect
# and occlusion paths, geometric normal, back faces, bent normals, per vertex, high to low) on a
# shared mesh. Run it with two builds and diff the lists to show a change keeps every output byte
# for byte:
#   AO=/tmp/old/ao bench/tools/output_digests.sh MESHES_DIR > old.txt
#   AO=build/src/ao bench/tools/output_digests.sh MESHES_DIR > new.txt && diff old.txt new.txt
# MESHES_DIR holds refined_elephant_uv.obj, ChineseDragon-10kv_uv.obj and ChineseDragon-10kv.off
# (default ../shared/data/meshes); THREADS (default 2) sets --threads.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
ao="${AO:-$here/../../build/src/ao}"
meshes="${1:-$here/../../../shared/data/meshes}"
threads="${THREADS:-2}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
run() { "$ao" --threads "$threads" -q "$@" >/dev/null 2>&1 || { echo "failed: ao $*" >&2; exit 1; }; }

size=(--width 160 --height 90)
for scene in default plane wedge sphere-on-plane box-room displaced; do
  run render "$scene" "${size[@]}" --spp 64 -o "$out/$scene-step.exr" --gbuffer-out "$out/$scene-gbuffer.exr" \
    --sun -1,0.6,0.5 --shaded "$out/$scene-shaded.png"
  run render "$scene" "${size[@]}" --spp 64 --membership linear -o "$out/$scene-linear.exr"
  run render "$scene" "${size[@]}" --spp 256 --target-error 0.02 -o "$out/$scene-adaptive.exr"
  run render "$scene" "${size[@]}" --spp 32 -p reference=tangent-sphere -o "$out/$scene-tangent.exr"
  run render "$scene" "${size[@]}" --spp 32 -p reference=transfer -o "$out/$scene-transfer-ref.exr"
done
run render "$meshes/ChineseDragon-10kv.off" "${size[@]}" --spp 64 -o "$out/dragon-step.exr" --gbuffer-out "$out/dragon-gbuffer.exr"

elephant="$meshes/refined_elephant_uv.obj"
bake=(bake "$elephant" -s 128 --padding 4)
run "${bake[@]}" -o "$out/bake-default.exr"
run "${bake[@]}" --denoise 0 -o "$out/bake-plain.exr" --bent-normals "$out/bake-bent.png"
run "${bake[@]}" --samples 24 --max-distance 0.3 --membership linear -o "$out/bake-linear.exr"
run "${bake[@]}" --samples 24 --normal geometric --ignore-back-faces -o "$out/bake-geometric.exr"
run "${bake[@]}" --samples 16 --floor -o "$out/bake-floor.exr"
run bake "$elephant" --samples 16 --per-vertex "$out/vertex.ply"
run bake "$elephant" --samples 16 --normal geometric --per-vertex "$out/vertex-geometric.ply"
run bake "$meshes/ChineseDragon-10kv_uv.obj" --high "$meshes/ChineseDragon-10kv.off" -s 128 --samples 32 --padding 4 \
  -o "$out/high-to-low.exr" --miss-mask "$out/high-to-low-miss.png"
run bake "$meshes/ChineseDragon-10kv_uv.obj" --high "$meshes/ChineseDragon-10kv.off" -s 128 --samples 32 --padding 4 \
  --denoise 0.75 --bent-normals "$out/high-to-low-bent.png" -o "$out/high-to-low-denoised.exr"
(cd "$out" && sha256sum -- *)
