// SPDX-License-Identifier: Apache-2.0
// What made an output: ao's version and SIMD target, the job, its input files with their SHA-256,
// and every setting of the request that can change the output. A job asked for it
// (RenderOutputs::provenance, BakeOutputs::provenance; `--provenance` on the command line) writes
// this record beside each output file as <output>.ao.json, in the same transaction as the outputs
// and renamed after them, so a record under its final name says that its output is complete and
// how it was made. A batch (python3 -m ao.batch) compares the record a rerun would write with the
// one on disk to tell an output made from the same inputs and settings from a stale one.
//
//   {"ao": {"version": "0.2.0", "simd_target": "AVX2"}, "job": "bake",
//    "output": {"file": "cow-ao.png", "bytes": 443120, "sha256": "..."},
//    "outputs": ["cow-ao.png"], "inputs": [{"role": "mesh", "path": "cow.obj", "bytes": 65012, "mtime_ns": ..., "sha256": "..."}],
//    "settings": {"method": "raytraced", "width": 1024, ...}}
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace ao {

class OutputSet;
struct Scene;

/// {"version": "0.2.0", "simd_target": "AVX2"}: the build and the kernels' target
/// (simd_target()) that made a result. Every JSON output of ao names it as "ao".
nlohmann::json build_info();

/// The SHA-256 of a file's bytes, as 64 lower-case hex digits (what `sha256sum` prints).
/// SystemError naming the file when it cannot be read.
std::string file_sha256(const std::filesystem::path& path);

/// The SHA-256 of a scene made in memory: every mesh's positions, normals, UVs, indices and
/// albedo, and every instance's mesh and transform, as stored (for a record of a render of a
/// scene the caller made, which has no file to hash).
std::string scene_sha256(const Scene& scene);

/// The files `mesh` reads: the file itself and, for a .gltf, the buffer files its "buffers" name
/// (relative URIs inside its folder; data: URIs are part of the file). A .gltf that cannot be
/// parsed names only itself (its loader reports it).
std::vector<std::filesystem::path> files_read_by(const std::filesystem::path& mesh);

/// An input of a record: {"role", "path" (as given), "bytes", "mtime_ns" (its modification time,
/// nanoseconds since 1970), "sha256"}.
struct ProvenanceInput {
  std::string role;  ///< "mesh", "camera", "high", ...: which request field named it.
  std::filesystem::path path;
};

/// <output>.ao.json: where the record of `output` is written ("cow-ao.png" -> "cow-ao.png.ao.json").
std::filesystem::path provenance_path(const std::filesystem::path& output);

/// The record of a job (the "output" member is added per file by stage_provenance): build_info(),
/// the job's name, each input with its size and SHA-256 (read now; only role and path unless
/// `hash_inputs`), and `settings`.
nlohmann::json provenance_record(std::string_view job, const std::vector<ProvenanceInput>& inputs, nlohmann::json settings, bool hash_inputs = true);

/// Stages <output>.ao.json for every output `outputs` has staged so far, each holding `record`
/// with "output": {"file", "bytes", "sha256"} of that output's staged bytes and "outputs": the
/// file names of the whole transaction. Call it after the last output is written and before
/// commit(), so the records are renamed after the outputs they describe.
void stage_provenance(OutputSet& outputs, const nlohmann::json& record);

/// Declares <output>.ao.json of each of `outputs` in `set` (same checks as the outputs).
void declare_provenance(OutputSet& set, const std::vector<std::filesystem::path>& outputs, const std::string& what);

}  // namespace ao
