#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes a GLB whose mesh 0 is used by three nodes side by side, from a GLB with one mesh (e.g. one
written by `ao bake mesh.obj --gltf in.glb`): the input of the glTF round-trip timing in docs/bake.md.
Usage: bench/tools/gltf_instances.py in.glb out.glb"""
import json
import struct
import sys

data = open(sys.argv[1], 'rb').read()
json_length = struct.unpack('<I', data[12:16])[0]
doc = json.loads(data[20:20 + json_length])
rest = data[20 + json_length:]  # the BIN chunk, header included
position = doc['accessors'][doc['meshes'][0]['primitives'][0]['attributes']['POSITION']]
width = position['max'][0] - position['min'][0]
doc['nodes'] = [{'name': 'A', 'mesh': 0}, {'name': 'B', 'mesh': 0, 'translation': [1.1 * width, 0, 0]},
                {'name': 'C', 'mesh': 0, 'translation': [-0.6 * width, 0, 0.5 * width]}]
doc['scenes'] = [{'nodes': [0, 1, 2]}]
doc['scene'] = 0
text = json.dumps(doc).encode()
text += b' ' * (-len(text) % 4)
out = b'glTF' + struct.pack('<II', 2, 12 + 8 + len(text) + len(rest)) + struct.pack('<I', len(text)) + b'JSON' + text + rest
open(sys.argv[2], 'wb').write(out)
