// SPDX-License-Identifier: Apache-2.0
// tinygltf 2.7 (Debian libtinygltf-dev, header only) compiled into ao's library, without its stb
// image decoder and encoder: images are kept encoded (gltf_document.cpp hands tinygltf a loader
// that copies the bytes), and nothing is ever written through it but the GLB stream.
// TINYGLTF_NO_STB_IMAGE and TINYGLTF_NO_STB_IMAGE_WRITE are set for all of ao's library
// (src/CMakeLists.txt): every file including tiny_gltf.h must agree on them. Included through
// tiny_gltf_internal.h, which keeps its symbols out of libao's exports.
#define TINYGLTF_IMPLEMENTATION
#include "ao/io/tiny_gltf_internal.h"
