// SPDX-License-Identifier: Apache-2.0
// Interleaved sampling (Keller and Heidrich 2001) as volumetric-ambient-occlusion (VAO) and
// ambient transfer (AT) use it, both in their sec. 4.2: the pixels of a 4x4 pattern use 16
// rotations of one sample set about the surface normal (VAO: about the view axis for the pipes'
// disk), repeated over the image; a 4x4 box filter then averages the 16 uncorrelated estimates,
// skipping neighbours whose depth differs from the centre's by more than a limit.
#pragma once

#include <array>
#include <span>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/image.h"
#include "ao/core/params.h"
#include "ao/methods/samples.h"

namespace ao {

/// Options common to the screen-space methods' sampling and filtering.
struct InterleaveOptions {
  bool interleave = true;          ///< 16 rotations in a 4x4 pattern (sec. 4.2); false: one rotation everywhere.
  bool filter = true;              ///< 4x4 depth-aware box filter after an interleaved pass (ignored without interleave).
  float filter_depth_limit = 0.0f; ///< Neighbours whose depth differs by more than this are skipped, world units; 0 = R/4.
};

/// The options' rows of a method's parameter table (core/params.h), for a Params struct P that
/// holds them in `member`: interleave, filter, filter_depth_limit.
template <class P>
std::vector<Param<P>> interleave_params(InterleaveOptions P::*member) {
  return {Param<P>::boolean("interleave", [member](P& p) -> bool& { return (p.*member).interleave; },
                            "sec. 4.2: 16 rotations in a 4x4 pattern; false: one rotation everywhere"),
          Param<P>::boolean("filter", [member](P& p) -> bool& { return (p.*member).filter; },
                            "4x4 depth-aware box filter after an interleaved pass (ignored without interleave)"),
          Param<P>::real("filter_depth_limit", [member](P& p) -> float& { return (p.*member).filter_depth_limit; }, Range::at_least(0),
                         "world units", "the filter skips neighbours whose depth differs by more than this; 0 = R/4")};
}
/// The depth limit the filter uses: `filter_depth_limit`, or R/4 when it is 0.
float effective_depth_limit(const InterleaveOptions& o, float radius);

/// 4x4 box filter of `image` over covered pixels, window offsets -2..+1 in x and y (so it holds each
/// of the 16 pattern positions once), skipping uncovered neighbours and those whose depth differs
/// from the centre pixel's by more than `depth_limit` (world units). Uncovered pixels keep their
/// value. Works for float and Vec3 images. `depth`: the G-buffer's depth_plane() when the caller
/// has built it for its own pass; null (the default): built here.
Image<float> depth_aware_box_filter(const Image<float>& image, const GBuffer& g, float depth_limit, const Image<float>* depth = nullptr);
Image<Vec3> depth_aware_box_filter(const Image<Vec3>& image, const GBuffer& g, float depth_limit, const Image<float>* depth = nullptr);
/// The same filter over planar float channels of one image (e.g. W's R, G, B and O), in place: each
/// tap's depth test is shared by up to 4 channels. Each plane gives what depth_aware_box_filter
/// would give for it alone. Planes must have the G-buffer's size (InputError otherwise).
void depth_aware_box_filter_planes(std::span<Image<float>* const> planes, const GBuffer& g, float depth_limit,
                                   const Image<float>* depth = nullptr);
/// The same over up to 4 planes from `src` into `dst` (each width * height floats of the
/// G-buffer's size, dst[c] != src[c]): what a caller that keeps its own storage uses.
void depth_aware_box_filter_planes(std::span<const float* const> src, std::span<float* const> dst, const GBuffer& g, float depth_limit,
                                   const Image<float>* depth = nullptr);

}  // namespace ao
