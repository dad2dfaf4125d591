#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `ao bake` against Blender Cycles' AO bake of the same mesh and UVs at equal error (BENCHMARKS.md,
# "bake"), single mesh or high to low. Needs Debian's blender and python3-numpy (not installed by
# scripts/setup: a benchmark check, not a dependency of ao).
#   [SAMPLES="32 64 128 256"] [AO_SETTINGS="24:0.75 64:0"] [ROUNDS=1] [HIGH=high.obj|high.off [LOW_RATIO=0.05]]
#   [CYCLES_REFERENCE=1024] bench/blender/compare.sh [MESH.obj|MESH.off] [SIZE] [OUT_DIR]
# Without HIGH: MESH (with UVs) is baked into its own UVs. With HIGH: high to low; MESH is the low
# mesh, or, when it is HIGH itself, the low mesh is made from it (bench/blender/make_low.py: Blender's
# Decimate to LOW_RATIO of the triangles, its UVs kept or Smart UV Project's), and both bakers
# push the low mesh out by the same cage distance (0.01 x its bounding-box diagonal, ao's default).
# Both bakers get 2 threads; each row is one run. Each round runs ao at each of AO_SETTINGS
# (RAYS:DENOISE[:CAGE_POINTS], rays per texel, --denoise sigma, high to low's --cage-points; by
# default the SAMPLES up to 128 at ao's default --denoise), then Blender at each of SAMPLES.
# Errors: RMSE over the texels both maps cover (bench/blender/rmse.py) against a converged,
# unfiltered ao bake (1024 rays per texel, another seed) and, with CYCLES_REFERENCE=N, against a
# Cycles bake at N samples; "mean - ref" is the map's mean minus the converged ao map's, beside the
# standard error of the map's mean (rmse.py). Time: the bake call itself, what bpy.ops.object.bake
# does (BVH, the texels the UVs cover, baking; ao: timings.bvh_ms (in bake_ms for high to low) + uv_coverage_ms + bake_ms +
# padding_ms, the filter included in bake_ms), and the whole process (load, BVH, bake, write) as
# wall and CPU (user + system) seconds.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
ao="${AO:-$here/../../build/src/ao}"
mesh="${1:-$here/../../../shared/data/meshes/refined_elephant_uv.obj}"
size="${2:-1024}"
out="${3:-$(mktemp -d)}"
mkdir -p "$out"
bl() { blender -b --factory-startup --python "$@" 2>/dev/null; }
now() { date +%s.%N; }
secs() { python3 -c "print(f'{$2 - $1:.2f}')"; }
# Runs a command, its CPU seconds (user + system, children included) into $out/cpu.
timed() { /usr/bin/time -f '%U %S' -o "$out/cpu.raw" "$@"; awk '{printf "%.2f", $1 + $2}' "$out/cpu.raw" > "$out/cpu"; }

h2l=() bl_h2l=()
if [ -n "${HIGH:-}" ]; then
  if [ "$mesh" = "$HIGH" ]; then
    low="$out/low.obj"
    [ -f "$low" ] || bl "$here/make_low.py" -- "$HIGH" "${LOW_RATIO:-0.05}" "$low" | grep '^triangles' >&2
    mesh="$low"
  fi
  cage=$(python3 -c "
import sys
v = [tuple(map(float, l.split()[1:4])) for l in open('$mesh') if l.startswith('v ')]
lo, hi = [min(c) for c in zip(*v)], [max(c) for c in zip(*v)]
print('%.6g' % (0.01 * sum((b - a) ** 2 for a, b in zip(lo, hi)) ** 0.5))")
  echo "high to low: $mesh from $HIGH, cage extrusion $cage" >&2
  h2l=(--high "$HIGH" --cage-extrusion "$cage")
  bl_h2l=("$HIGH" "$cage")
fi

if [ ! -f "$out/reference.exr" ]; then
  echo "reference: ao bake, 1024 rays per texel" >&2
  ref_points=()
  [ -n "${HIGH:-}" ] && ref_points=(--cage-points 64)
  "$ao" --threads 2 bake "$mesh" "${h2l[@]}" "${ref_points[@]}" -s "$size" --samples 1024 --seed 99 --padding 0 --denoise 0 -o "$out/reference.exr" >&2
fi
if [ -n "${CYCLES_REFERENCE:-}" ] && [ ! -f "$out/cycles-reference.exr" ]; then
  echo "reference: Cycles, $CYCLES_REFERENCE samples" >&2
  bl "$here/bake_ao.py" -- "$mesh" "$size" "$CYCLES_REFERENCE" "$out/cycles-reference.exr" 2 "${bl_h2l[@]}" >/dev/null
fi
errors() {
  local ao_ref cy="-"
  ao_ref=$(bl "$here/rmse.py" -- "$1" "$out/reference.exr" | sed -n 's/^rmse \([0-9.]*\) texels [0-9]* mean_signed \([-+0-9.]*\) se \([0-9.]*\).*/\1 | \2 | \3/p')
  [ -f "$out/cycles-reference.exr" ] && cy=$(bl "$here/rmse.py" -- "$1" "$out/cycles-reference.exr" | sed -n 's/^rmse \([0-9.]*\).*/\1/p')
  echo "$ao_ref | $cy"
}

echo "| baker | setting | RMSE vs ao converged | mean - ref | SE of mean | RMSE vs Cycles converged | bake s | process s | process CPU s |"
echo "|---|---|---:|---:|---:|---:|---:|---:|---:|"
settings="${AO_SETTINGS:-}"
if [ -z "$settings" ]; then
  for spp in ${SAMPLES:-32 64 128 256}; do [ "$spp" -le 128 ] && settings="$settings $spp:default"; done
fi
for round in $(seq "${ROUNDS:-1}"); do
for setting in $settings; do
  IFS=: read -r spp sigma points <<< "$setting"
  args=(--samples "$spp")
  [ "$sigma" != default ] && args+=(--denoise "$sigma")
  [ -n "$points" ] && args+=(--cage-points "$points")
  name="ao-$spp-$sigma-${points:-d}"
  t0=$(now)
  timed "$ao" --threads 2 bake "$mesh" "${h2l[@]}" -s "$size" "${args[@]}" --padding 0 -o "$out/$name.exr" --json > "$out/$name.json" 2>/dev/null
  t1=$(now)
  bake=$(python3 -c 'import json,sys; t=json.load(open(sys.argv[1]))["timings"]; print("%.2f" % ((t.get("bvh_ms", 0) + t["uv_coverage_ms"] + t["bake_ms"] + t["padding_ms"]) / 1000))' "$out/$name.json")
  sigma_used=$(python3 -c 'import json,sys; p = json.load(open(sys.argv[1]))["parameters"]; print(p.get("denoise", p.get("ao", {}).get("denoise")))' "$out/$name.json")
  echo "| ao | $spp rays/texel, --denoise $sigma_used${points:+, --cage-points $points} | $(errors "$out/$name.exr") | $bake | $(secs "$t0" "$t1") | $(cat "$out/cpu") |"
done
for spp in ${SAMPLES:-32 64 128 256}; do
  t0=$(now)
  timed blender -b --factory-startup --python "$here/bake_ao.py" -- "$mesh" "$size" "$spp" "$out/blender-$spp.exr" 2 "${bl_h2l[@]}" > "$out/blender.log" 2>/dev/null
  t1=$(now)
  bake=$(sed -n 's/^bake_seconds //p' "$out/blender.log")
  echo "| Blender Cycles | $spp samples | $(errors "$out/blender-$spp.exr") | $bake | $(secs "$t0" "$t1") | $(cat "$out/cpu") |"
done
done
