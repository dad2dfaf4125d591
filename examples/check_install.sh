#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The library boundary, checked as a user meets it (run by CTest as `install_and_examples` and
# `installed_headers_without_embree`, or by hand: examples/check_install.sh BUILD_DIR [examples|headers]):
#   1. installs the build into a temporary prefix, which carries the licence and its notice, man
#      pages and bash and zsh completion for ao and each subcommand, and whose libao has no tinygltf
#      symbol (nm);
# examples (the default):
#   2. builds examples/ as a separate CMake project with find_package(ao 0.2 REQUIRED), with
#      AddressSanitizer and UndefinedBehaviorSanitizer (the library's memory is checked through
#      ASan's allocator: a reference kept into a freed result fails), and runs the four programs
#      on a small OBJ written here (a floor with UVs and a cube on it), checking what they print;
#   3. builds a one-file program with `pkg-config --cflags --libs ao` and runs it, sanitized too;
# headers:
#   4. checks that ao/ao.h includes every other installed header, and compiles every installed
#      header in one translation unit with Embree's, assimp's, OpenEXR's, libpng's and FreeType's
#      headers replaced by ones that fail: no installed header includes them; and compiles ao/ao.h
#      included plainly with -Wall -Wextra -Wconversion -Wshadow -Werror by the build's compiler
#      and by g++ and clang++ where installed; and compiles the program that renders through
#      ao/jobs/render.h alone (mesh_to_exr.cpp) with <nlohmann/json.hpp> replaced by a header that fails: a job's
#      header costs a translation unit no JSON parser (docs/architecture.md, "Layers").
# Everything is written below a temporary folder, removed at the end.
set -euo pipefail
build=$(cd "${1:?usage: check_install.sh BUILD_DIR [examples|headers]}" && pwd)
mode=${2:-examples}
src=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
cxx=${CXX:-c++}

echo "== install into $prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
for f in LICENSE NOTICE; do
  [ -s "$prefix/share/doc/ao/$f" ] || { echo "check_install: share/doc/ao/$f was not installed" >&2; exit 1; }
done
echo "== libao exports no tinygltf symbol"
libs=$(find "$prefix" -type f \( -name 'libao*.a' -o -name 'libao*.so*' \))
[ -n "$libs" ] || { echo "check_install: no libao installed" >&2; exit 1; }
for lib in $libs; do
  nm -C "$lib" > "$tmp/symbols" 2>/dev/null
  if grep -E -m 3 '(^|[^_[:alnum:]:])tinygltf::' "$tmp/symbols"; then echo "check_install: $lib has tinygltf symbols" >&2; exit 1; fi
  # A shared library's exports: tinygltf, renamed into ao::gltf_detail, is hidden.
  case $lib in *.so*)
    nm -D -C --defined-only "$lib" > "$tmp/exports"
    if grep -m 3 gltf_detail "$tmp/exports"; then echo "check_install: $lib exports tinygltf" >&2; exit 1; fi ;;
  esac
done
echo "== man pages and bash and zsh completion for ao and every subcommand"
subcommands=$("$prefix/bin/ao" --help | sed -n '/^Subcommands:/,$p' | awk 'NR > 1 && /^  [a-z]/ { print $1 }')
[ -n "$subcommands" ] || { echo "check_install: no subcommands in ao --help" >&2; exit 1; }
completion=$prefix/share/bash-completion/completions/ao
[ -s "$completion" ] || { echo "check_install: no bash completion installed" >&2; exit 1; }
[ -s "$prefix/share/man/man1/ao.1" ] || { echo "check_install: no man page ao.1 installed" >&2; exit 1; }
for s in $subcommands; do
  grep -q "ao-$s(1)" "$prefix/share/man/man1/ao.1" || { echo "check_install: ao.1 does not mention ao-$s(1)" >&2; exit 1; }
  grep -q "^\.TH AO-${s^^} " "$prefix/share/man/man1/ao-$s.1" || { echo "check_install: no man page ao-$s.1" >&2; exit 1; }
  grep -q "^    $s)$" "$completion" || { echo "check_install: the completion does not know $s" >&2; exit 1; }
  grep -q "^  $s)$" "$prefix/share/zsh/vendor-completions/_ao" || { echo "check_install: the zsh completion does not know $s" >&2; exit 1; }
done
grep -q -- "--spp" "$completion" || { echo "check_install: the completion lacks render's options" >&2; exit 1; }
PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name ao.pc)")"
export PKG_CONFIG_PATH

if [ "$mode" = examples ]; then
echo "== examples/ as a separate project (find_package(ao 0.2 REQUIRED)), under AddressSanitizer"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
sanitize="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
# Release (no -g) and CCACHE_BASEDIR: ccache then finds the objects of an earlier run, whose
# temporary folder differed.
export CCACHE_BASEDIR="$tmp"
cmake -S "$src" -B "$tmp/examples" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$sanitize" -DCMAKE_EXE_LINKER_FLAGS="$sanitize" >/dev/null
cmake --build "$tmp/examples" >/dev/null
# Any ASan report ends the program with an error; leaks inside the libraries ao uses are listed in
# tests/lsan.supp.
export ASAN_OPTIONS=abort_on_error=0:halt_on_error=1:exitcode=99
export LSAN_OPTIONS="suppressions=$src/../tests/lsan.supp"

cat > "$tmp/scene.obj" <<'OBJ'
o floor
v -2 0 -2
v 2 0 -2
v 2 0 2
v -2 0 2
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 1 0
f 1/1/1 4/4/1 3/3/1 2/2/1
o cube
v -0.5 0 -0.5
v 0.5 0 -0.5
v 0.5 1 -0.5
v -0.5 1 -0.5
v -0.5 0 0.5
v 0.5 0 0.5
v 0.5 1 0.5
v -0.5 1 0.5
f 5 8 7 6
f 9 10 11 12
f 5 6 10 9
f 8 12 11 7
f 5 9 12 8
f 6 7 11 10
OBJ
head -n 11 "$tmp/scene.obj" > "$tmp/low.obj"  # the floor alone: the low mesh the floor and cube are baked into
cd "$tmp"
"$tmp/examples/mesh_to_exr" scene.obj ao.exr volumetric
"$tmp/examples/own_gbuffer"
"$tmp/examples/bake_map" scene.obj map.png 64
"$tmp/examples/bake_high_to_low" low.obj scene.obj 64 | tee high_to_low.txt
# The floor's texels under the cube see no high surface, the others do: some texels, not 0.
grep -Eq '^low_ao.png: [1-9][0-9]* texels from the high mesh' high_to_low.txt || { echo "check_install: bake_high_to_low baked no texel" >&2; exit 1; }
for f in ao.exr own_gbuffer.pgm map.png low_ao.png high_ao.ply; do [ -s "$f" ] || { echo "check_install: $f was not written" >&2; exit 1; }; done

echo "== a one-file program with pkg-config --cflags --libs ao"
cat > "$tmp/version.cpp" <<'CPP'
#include <cstdio>
#include <ao/ao.h>
int main() {
  const ao::Scene scene = ao::make_builtin_scene("plane");
  std::printf("ao %d.%d.%d, %zu triangles\n", AO_VERSION_MAJOR, AO_VERSION_MINOR, AO_VERSION_PATCH, scene.triangle_count());
  return AO_VERSION_MAJOR * 100 + AO_VERSION_MINOR == 2 ? 0 : 1;
}
CPP
# shellcheck disable=SC2046,SC2086
"$cxx" $sanitize -o "$tmp/version" "$tmp/version.cpp" $(pkg-config --cflags --libs ao)
"$tmp/version"
echo "check_install: examples passed"
exit 0
fi

echo "== installed headers, without Embree, assimp, OpenEXR, libpng, FreeType"
poison=$tmp/poison
for h in embree3/rtcore.h embree3/rtcore_ray.h assimp/scene.h assimp/Importer.hpp OpenEXR/ImfHeader.h \
         OpenEXR/ImfInputFile.h OpenEXR/ImfFrameBuffer.h png.h ft2build.h; do
  mkdir -p "$poison/$(dirname "$h")"
  echo "#error \"an installed ao header includes <$h>\"" > "$poison/$h"
done
(cd "$prefix/include" && find ao -name '*.h' | sort | sed 's/.*/#include <&>/') > "$tmp/all_headers.cpp"
[ "$(grep -c . "$tmp/all_headers.cpp")" -gt 10 ] || { echo "check_install: too few headers installed" >&2; exit 1; }
if grep -q "_internal.h" "$tmp/all_headers.cpp"; then echo "check_install: an internal header was installed" >&2; exit 1; fi
echo "== ao/ao.h names every installed header"
missing=$(cd "$prefix/include" && for h in $(find ao -name '*.h' ! -path ao/ao.h | sort); do grep -q "^#include \"$h\"" ao/ao.h || echo "$h"; done)
[ -z "$missing" ] || { echo "check_install: ao/ao.h does not include:" $missing >&2; exit 1; }
"$cxx" -std=c++20 -fsyntax-only -I"$poison" -I"$prefix/include" $(pkg-config --cflags-only-other tbb nlohmann_json) "$tmp/all_headers.cpp"
echo "== ao/ao.h included plainly (-I, not -isystem) is warning-free: -Wall -Wextra -Wconversion -Wshadow, GCC and Clang"
printf '#include <ao/ao.h>\nint main() { return 0; }\n' > "$tmp/umbrella.cpp"
compilers=("$cxx")
for c in g++ clang++; do command -v "$c" >/dev/null && [ "$(command -v "$c")" != "$(command -v "$cxx")" ] && compilers+=("$c"); done
for c in "${compilers[@]}"; do
  "$c" -std=c++20 -fsyntax-only -Wall -Wextra -Wconversion -Wshadow -Werror -I"$prefix/include" $(pkg-config --cflags-only-other tbb nlohmann_json) "$tmp/umbrella.cpp" ||
    { echo "check_install: ao/ao.h warns under $c (above)" >&2; exit 1; }
  echo "   $c: no warning"
done
echo "== a translation unit that renders includes no nlohmann/json.hpp"
mkdir -p "$poison/nlohmann"
echo '#error "ao/jobs/render.h includes <nlohmann/json.hpp>"' > "$poison/nlohmann/json.hpp"
for c in "${compilers[@]}"; do
  "$c" -std=c++20 -fsyntax-only -Wall -Wextra -Werror -I"$poison" -I"$prefix/include" $(pkg-config --cflags-only-other tbb) "$src/mesh_to_exr.cpp" ||
    { echo "check_install: a program that renders needs <nlohmann/json.hpp> under $c (above)" >&2; exit 1; }
  echo "   $c: compiles without it"
done
echo "check_install: headers passed"
