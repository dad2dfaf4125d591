// SPDX-License-Identifier: Apache-2.0
// tinygltf 2.7 (Debian libtinygltf-dev, header only) as ao's library compiles it: every file that
// uses tinygltf includes it through here, never <tiny_gltf.h> itself. Its namespace is renamed to
// ao::gltf_detail and its declarations get hidden visibility, so that libao exports no tinygltf
// symbol: a program with its own tinygltf (another version, other switches) keeps its own copy
// instead of linking against ours, and the shared library's symbol table holds only the ao API.
// The headers tinygltf includes come first, outside the hidden region, so that they keep their
// default visibility. Not installed.
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

// A nested namespace definition (C++17): tiny_gltf.h's `namespace tinygltf {` opens
// ao::gltf_detail, and its qualified names (tinygltf::Model) name the same.
#define tinygltf ao::gltf_detail
#pragma GCC visibility push(hidden)
#include <tiny_gltf.h>
#pragma GCC visibility pop
