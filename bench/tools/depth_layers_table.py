#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Error and time of the screen-space methods with one and two depth layers (docs/methods/depth-layers.md).

    bench/tools/depth_layers_table.py BUILD/src/ao [--meshes ../shared/data/meshes] [--out-dir DIR]

Runs `ao compare` (640x360, R = 0.1 x the objects' diagonal, 256 reference rays per pixel, seed 1)
on three built-in scenes and three shared meshes, for each configuration below, and prints one
markdown table: RMSE against each method's matched reference, and the method's milliseconds
(wall time of its pass, second-layer trace included; noisy on a shared machine). The errors are
deterministic; the times are indicative only. Outputs go to a temporary folder unless --out-dir.
"""
import argparse
import json
import os
import subprocess
import tempfile

CONFIGS = [
    ("1 layer (defaults)", []),
    ("2 layers", ["-p", "layers=2"]),
    ("1 layer, ray_steps=8", ["-p", "ray_steps=8"]),
    ("2 layers, ray_steps=8", ["-p", "layers=2", "-p", "ray_steps=8"]),
]
METHODS = "containment,volumetric,transfer,alchemy"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ao")
    ap.add_argument("--meshes", default=os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "meshes"))
    ap.add_argument("--out-dir")
    a = ap.parse_args()
    scenes = ["default", "box-room", "sphere-on-plane"] + [os.path.join(a.meshes, m) for m in ("ChineseDragon-10kv.off", "pinion.off", "rotor_small.off")]
    out = a.out_dir or tempfile.mkdtemp(prefix="ao-layers-")
    rows = {}
    for scene in scenes:
        for label, extra in CONFIGS:
            cmd = [a.ao, "compare", scene, "--methods", METHODS, "--common-reference", "none", "--out-dir", os.path.join(out, "run"), "--json"] + extra
            table = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
            for r in table["rows"]:
                # ray_steps is containment's and transfer's: the other methods' rows repeat the config without it.
                if "ray_steps" in " ".join(extra) and r["method"] not in ("containment", "transfer"):
                    continue
                rows.setdefault((os.path.basename(scene), r["method"]), []).append((label, r["rmse"], r["ms"]))
    print("| scene | method | " + " | ".join(label for label, _ in CONFIGS) + " |")
    print("|---|---|" + "---:|" * len(CONFIGS))
    for (scene, method), cells in rows.items():
        by = {label: "%.4f (%.0f ms)" % (e, ms) for label, e, ms in cells}
        print("| %s | %s | %s |" % (scene, method, " | ".join(by.get(label, "") for label, _ in CONFIGS)))


if __name__ == "__main__":
    main()
