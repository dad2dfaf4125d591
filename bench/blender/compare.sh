#!/usr/bin/env bash
# `ao bake` against Blender Cycles' AO bake of the same mesh and UVs at equal error (BENCHMARKS.md,
# "bake"). Needs Debian's blender and python3-numpy (not installed by scripts/setup: a benchmark
# check, not a dependency of ao).
#   [SAMPLES="32 64 128 256"] [AO_SETTINGS="24:0.75 64:0"] [ROUNDS=1] bench/blender/compare.sh [MESH.obj] [SIZE] [OUT_DIR]
# Both bakers get 2 threads; each row is one run. Each round runs ao at each of AO_SETTINGS
# (RAYS:DENOISE, rays per texel and --denoise sigma; by default the SAMPLES up to 128 at ao's
# default --denoise), then Blender at each of SAMPLES. Error: RMSE against a
# converged ao bake (1024 rays per texel, unfiltered) over the texels both maps cover (bench/blender/rmse.py).
# Time: the bake call itself, what bpy.ops.object.bake does (BVH, the texels the UVs cover, baking;
# ao: timings.bvh_ms + uv_coverage_ms + bake_ms + padding_ms, the filter included in bake_ms), and
# the whole process (load, BVH, bake, write) as wall seconds.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
ao="${AO:-$here/../../build/src/ao}"
mesh="${1:-$here/../../../shared/data/meshes/refined_elephant_uv.obj}"
size="${2:-1024}"
out="${3:-$(mktemp -d)}"
mkdir -p "$out"
bl() { blender -b --factory-startup --python "$@" 2>/dev/null; }
rmse() { bl "$here/rmse.py" -- "$1" "$out/reference.exr" | sed -n 's/^rmse \([0-9.]*\).*/\1/p'; }
now() { date +%s.%N; }

if [ ! -f "$out/reference.exr" ]; then
  echo "reference: ao bake, 1024 rays per texel" >&2
  "$ao" --threads 2 bake "$mesh" -s "$size" --samples 1024 --seed 99 --padding 0 --denoise 0 -o "$out/reference.exr" >&2
fi

echo "| baker | setting | RMSE | bake s | process s |"
echo "|---|---|---:|---:|---:|"
secs() { python3 -c "print(f'{$2 - $1:.2f}')"; }
settings="${AO_SETTINGS:-}"
if [ -z "$settings" ]; then
  for spp in ${SAMPLES:-32 64 128 256}; do [ "$spp" -le 128 ] && settings="$settings $spp:default"; done
fi
for round in $(seq "${ROUNDS:-1}"); do
for setting in $settings; do
  spp="${setting%%:*}" sigma="${setting#*:}"
  args=(--samples "$spp")
  [ "$sigma" != default ] && args+=(--denoise "$sigma")
  t0=$(now)
  json=$("$ao" --threads 2 bake "$mesh" -s "$size" "${args[@]}" --padding 0 -o "$out/ao-$spp-$sigma.exr" --json 2>/dev/null)
  t1=$(now)
  bake=$(printf '%s' "$json" | python3 -c 'import json,sys; t=json.load(sys.stdin)["timings"]; print("%.2f" % ((t["bvh_ms"] + t["uv_coverage_ms"] + t["bake_ms"] + t["padding_ms"]) / 1000))')
  sigma_used=$(printf '%s' "$json" | python3 -c 'import json,sys; print(json.load(sys.stdin)["parameters"]["denoise"])')
  echo "| ao | $spp rays/texel, --denoise $sigma_used | $(rmse "$out/ao-$spp-$sigma.exr") | $bake | $(secs "$t0" "$t1") |"
done
for spp in ${SAMPLES:-32 64 128 256}; do
  t0=$(now)
  bake=$(bl "$here/bake_ao.py" -- "$mesh" "$size" "$spp" "$out/blender-$spp.exr" 2 | sed -n 's/^bake_seconds //p')
  t1=$(now)
  echo "| Blender Cycles | $spp samples | $(rmse "$out/blender-$spp.exr") | $bake | $(secs "$t0" "$t1") |"
done
done
