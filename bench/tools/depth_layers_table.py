#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Error and time of the screen-space methods with one and two depth layers (docs/methods/depth-layers.md).

    bench/tools/depth_layers_table.py BUILD/src/ao [--meshes ../shared/data/meshes] [--out-dir DIR]
    bench/tools/depth_layers_table.py BUILD/src/ao --thickness [--open-sheets DIR] [--methods gtao]

Runs `ao compare` (640x360, R = 0.1 x the objects' diagonal, 256 reference rays per pixel, seed 1)
on three built-in scenes and three shared meshes, for each configuration below, and prints one
markdown table: RMSE against each method's matched reference, and the method's milliseconds
(wall time of its pass, second-layer trace included; noisy on a shared machine). The errors are
deterministic; the times are indicative only. Outputs go to a temporary folder unless --out-dir.

--thickness compares one layer, two layers and one layer's sheets of thickness R/8, R/4 and R/2
(containment, volumetric, transfer, or --methods) instead; --open-sheets DIR adds the meshes `ao_open_sheets DIR`
wrote (the open-mesh suite and its closed meshes), each with its camera.
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
# One layer's sheets: the thickness as a fraction of the scene's R (the compare's own radius).
THICKNESS_CONFIGS = [("1 layer", [], None), ("2 layers", ["-p", "layers=2"], None)] + [
    ("thickness R/%d" % k, [], 1.0 / k) for k in (8, 4, 2)]
SUITE = ["box", "sphere", "torus", "head", "arch", "bowl", "open-box", "mask", "dome", "terrain", "tablecloth", "leaf", "gutter"]


def compare(a, scene_args, methods, extra, out):
    cmd = [a.ao, "compare"] + scene_args + ["--methods", methods, "--common-reference", "none", "--out-dir", os.path.join(out, "run"), "--json"]
    return json.loads(subprocess.run(cmd + extra, check=True, capture_output=True, text=True).stdout)


def thickness_table(a, scenes, out):
    labels = [label for label, _, _ in THICKNESS_CONFIGS]
    print("| scene | method | " + " | ".join(labels) + " |")
    print("|---|---|" + "---:|" * len(labels))
    for name, args in scenes:
        cells = {}
        radius = None
        for label, extra, fraction in THICKNESS_CONFIGS:
            if fraction is not None:
                extra = ["-p", "thickness=%.6g" % (fraction * radius)]
            table = compare(a, args, a.methods, extra, out)
            radius = table["radius"]
            for r in table["rows"]:
                cells.setdefault(r["method"], []).append("%.4f" % r["rmse"])
        for method, row in cells.items():
            print("| %s | %s | %s |" % (name, method, " | ".join(row)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ao")
    ap.add_argument("--meshes", default=os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "meshes"))
    ap.add_argument("--out-dir")
    ap.add_argument("--thickness", action="store_true", help="one layer's sheets of a thickness against one and two layers")
    ap.add_argument("--open-sheets", help="a folder ao_open_sheets wrote: add its meshes, each with its camera")
    ap.add_argument("--methods", default="containment,volumetric,transfer", help="with --thickness: the methods compared")
    a = ap.parse_args()
    scenes = ["default", "box-room", "sphere-on-plane"] + [os.path.join(a.meshes, m) for m in ("ChineseDragon-10kv.off", "pinion.off", "rotor_small.off")]
    named = [(os.path.basename(s), [s]) for s in scenes]
    if a.open_sheets:
        named += [(n, [os.path.join(a.open_sheets, n + ".obj"), "--camera", os.path.join(a.open_sheets, n + ".camera.json")]) for n in SUITE]
    out = a.out_dir or tempfile.mkdtemp(prefix="ao-layers-")
    if a.thickness:
        return thickness_table(a, named, out)
    rows = {}
    for name, args in named:
        for label, extra in CONFIGS:
            table = compare(a, args, METHODS, extra, out)
            for r in table["rows"]:
                # ray_steps is containment's and transfer's: the other methods' rows repeat the config without it.
                if "ray_steps" in " ".join(extra) and r["method"] not in ("containment", "transfer"):
                    continue
                rows.setdefault((name, r["method"]), []).append((label, r["rmse"], r["ms"]))
    print("| scene | method | " + " | ".join(label for label, _ in CONFIGS) + " |")
    print("|---|---|" + "---:|" * len(CONFIGS))
    for (scene, method), cells in rows.items():
        by = {label: "%.4f (%.0f ms)" % (e, ms) for label, e, ms in cells}
        print("| %s | %s | %s |" % (scene, method, " | ".join(by.get(label, "") for label, _ in CONFIGS)))


if __name__ == "__main__":
    main()
