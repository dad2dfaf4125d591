#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Cold-process comparison of `ao render --method raytraced` with the bare Embree loop (ao_bare):
#   bench/bare/cold.sh MESH.off [ROUNDS]
# puts MESH on a ground quad three times its footprint (as bench_scenes.h), runs both processes
# alternately ROUNDS times (default 3) at 1280x720, 64 rays per pixel, the camera and R of ao's
# JSON, and prints the G-buffer / primary-pass and AO-pass times and their ratios.
# Needs python3 (JSON and the OFF bounds). Writes only to a temporary directory.
set -euo pipefail
here="$(cd "$(dirname "$0")/../.." && pwd)"
ao="$here/build/src/ao"; bare="$here/build/bench/ao_bare"
mesh="$1"; rounds="${2:-3}"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
python3 - "$mesh" "$tmp/ground.obj" <<'PY'
import sys
t = open(sys.argv[1]).read().split()
assert t[0] == 'OFF'
nv = int(t[1]); v = [float(x) for x in t[4:4 + 3 * nv]]
lo = [min(v[i::3]) for i in range(3)]; hi = [max(v[i::3]) for i in range(3)]
c = [(a + b) / 2 for a, b in zip(lo, hi)]; e = [(b - a) * 1.5 for a, b in zip(lo, hi)]
y = lo[1]
with open(sys.argv[2], 'w') as f:
    for sx, sz in ((-1, 1), (1, 1), (1, -1), (-1, -1)):
        f.write('v %r %r %r\n' % (c[0] + sx * e[0], y, c[2] + sz * e[2]))
    f.write('f 1 2 3\nf 1 3 4\n')
PY
"$ao" render "$mesh" "$tmp/ground.obj" --spp 64 --json -q -o "$tmp/v.png" > "$tmp/ao.json"
read -r eye target fov radius <<< "$(python3 -c "
import json; d = json.load(open('$tmp/ao.json')); c = d['camera']
print(','.join(map(repr, c['eye'])), ','.join(map(repr, c['target'])), c['fov'], d['radius'])")"
for _ in $(seq "$rounds"); do
  "$ao" render "$mesh" "$tmp/ground.obj" --spp 64 --json -q -o "$tmp/v.png" > "$tmp/ao.json"
  "$bare" "$mesh" "$tmp/ground.obj" --eye "$eye" --target "$target" --fov "$fov" --radius "$radius" --spp 64 > "$tmp/bare.json"
  python3 -c "
import json; a = json.load(open('$tmp/ao.json')); b = json.load(open('$tmp/bare.json')); t = a['timings']
print('ao: G-buffer %.1f ms, AO %.1f ms, V %.5f | bare: primary %.1f ms, AO %.1f ms, V %.5f | G-buffer ao/bare %.2f, AO bare/ao %.2f'
      % (t['gbuffer_ms'], t['ao_ms'], a['mean_visibility'], b['primary_ms'], b['ao_ms'], b['mean_visibility'],
         t['gbuffer_ms'] / b['primary_ms'], b['ao_ms'] / t['ao_ms']))"
done
