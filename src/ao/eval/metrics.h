// SPDX-License-Identifier: Apache-2.0
// Image quality metrics between a method's visibility and its reference, over the pixels a mask
// selects (the G-buffer's coverage: background pixels say nothing about a method).
#pragma once

#include <cstdint>

#include <nlohmann/json.hpp>

#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

struct ErrorMetrics {
  double rmse = 0;          ///< Root mean squared error, in V units.
  double psnr_db = 0;       ///< 10 log10(1 / MSE), peak 1; +infinity for identical images.
  double ssim = 1;          ///< Mean SSIM (Wang et al. 2004): 11x11 Gaussian window, sigma 1.5, peak 1.
  double mean_signed = 0;   ///< Mean of (image - reference): > 0 means the method is too bright.
  double max_abs = 0;       ///< Largest absolute difference.
  std::size_t pixels = 0;   ///< Pixels compared.
};
void to_json(nlohmann::json& j, const ErrorMetrics& m);

/// Metrics of `image` against `reference` over pixels where mask != 0 (all pixels when `mask` is
/// empty). Images must have the same size (InputError otherwise). SSIM windows are evaluated at
/// every masked pixel over masked neighbours only, so the background does not inflate it.
ErrorMetrics compare_images(const Image<float>& image, const Image<float>& reference, const Image<std::uint8_t>& mask = {});

/// Colour of one signed error (image - reference) in signed_error_heat_map: white at 0, towards
/// pure red at +range (the image is too bright) and pure blue at -range (too dark), saturated beyond.
/// `range` > 0.
Vec3 signed_error_colour(float error, float range);

/// Signed error heat map for people: blue where the image is darker than the reference, red where
/// brighter, white where equal (signed_error_colour); `range` is the |error| shown at full saturation.
/// Unmasked pixels are mid grey.
Image<Vec3> signed_error_heat_map(const Image<float>& image, const Image<float>& reference, const Image<std::uint8_t>& mask = {},
                                  float range = 0.25f);

}  // namespace ao
