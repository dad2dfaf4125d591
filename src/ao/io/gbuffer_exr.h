// SPDX-License-Identifier: Apache-2.0
// G-buffers as multi-channel OpenEXR files: what `ao render` can save and what a compositor
// supplies to run the screen-space methods on another renderer's passes. Channel names,
// conventions and how Blender and Nuke passes map onto them: docs/gbuffer.md.
#pragma once

#include <filesystem>
#include <optional>

#include "ao/core/gbuffer.h"

namespace ao {

/// Which optional parts write_gbuffer_exr stores. All on by default; turning parts off makes
/// smaller files holding what another renderer typically provides (read_gbuffer_exr fills the rest).
struct GBufferWriteOptions {
  bool positions = true;   ///< P.X P.Y P.Z (else rebuilt from Z and the camera on reading).
  bool albedo = true;      ///< albedo.R albedo.G albedo.B.
  bool object_ids = true;  ///< id.
  bool primitive_ids = true;  ///< primid (triangle index within mesh id - 1), when the G-buffer has one.
  bool coverage = true;    ///< A.
  bool camera = true;      ///< worldToCamera and the ao:* camera attributes (fov included).
  bool direct = true;      ///< direct.R direct.G direct.B, when the G-buffer has a direct-light pass.
  /// P and N in world space (as Blender writes them; read them with GBufferReadOptions::world_space),
  /// through the camera's placement; Z stays linear camera depth. Default false: camera space.
  bool world_space = false;
};

/// Writes every G-buffer channel (P.X P.Y P.Z, Z, N.X N.Y N.Z, albedo.R albedo.G albedo.B as
/// FLOAT; id as UINT; A = coverage as FLOAT 0/1; direct.R direct.G direct.B as FLOAT when
/// gbuffer.direct is not empty; primid as UINT when gbuffer.primitive_id is not empty) to one scanline, ZIP-compressed EXR, with the
/// camera in the header: the standard `worldToCamera` matrix (OpenEXR's left-handed camera space,
/// see docs/gbuffer.md) and `ao:verticalFov` (degrees), `ao:eye`, `ao:target`, `ao:up` (world units).
/// Values are written exactly, +infinity background depth included. The images must all have the
/// camera's size (InputError otherwise). Writes atomically (atomic_file.h). `opt` can leave out
/// the optional channels and the camera; Z and N.* are always written.
void write_gbuffer_exr(const std::filesystem::path& path, const GBuffer& gbuffer, const GBufferWriteOptions& opt = {});

/// How a G-buffer EXR from elsewhere is interpreted.
struct GBufferReadOptions {
  /// Full vertical field of view, degrees, in (0, 180). When set it replaces the file's
  /// `ao:verticalFov`; a file without that attribute needs it (the CLI's --fov). Default: from the file.
  std::optional<float> vertical_fov_deg;
  /// The file's N.* (and P.*, when present) channels are in world space, like Blender's Normal and
  /// Position passes: move them into camera space with the file's camera, which must then be in
  /// the header. Default false: they are in camera space.
  bool world_space = false;
  /// Without an `A` channel, pixels whose Z is finite, > 0 and below this are covered, world units.
  /// Default 1e9: renderers mark background with huge depths (Blender writes 1e10).
  float background_depth = 1e9f;
};

/// Reads a G-buffer EXR. Requires channels Z and N.X N.Y N.Z; the others are optional:
/// - P.*: reconstructed from Z through each pixel centre (P = camera_direction(x+0.5, y+0.5) * Z);
/// - A: covered where Z is finite, > 0 and below `background_depth`; with A, covered where A >= 0.5;
/// - albedo.*: 0.8 grey where covered; id: 1 where covered;
/// - primid: the triangle index (GBuffer::primitive_id); without it primitive_id stays empty;
/// - direct.*: the direct-light pass (Ld / La, GBuffer::direct); without them GBuffer::direct
///   stays empty. Some but not all three is an error; at covered pixels they must be finite, >= 0.
/// The image is the display window (pixels outside the data window are background). The camera
/// comes from `ao:eye/target/up`, else from `worldToCamera`, else world space is camera space
/// (eye at the origin looking down -z). At covered pixels Z must be finite and > 0, and P, N and
/// albedo finite, N non-zero (it is renormalised); else InputError naming the pixel. Uncovered
/// pixels get the GBuffer background values whatever the file holds.
/// Throws InputError of one line naming the file for a missing, truncated or malformed file,
/// missing channels (listed), an absurd size (> 32768 per side or 2^28 pixels, checked before
/// allocating), or a missing field of view ("pass --fov").
GBuffer read_gbuffer_exr(const std::filesystem::path& path, const GBufferReadOptions& opt = {});

}  // namespace ao
