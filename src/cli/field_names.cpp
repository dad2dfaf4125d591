// SPDX-License-Identifier: Apache-2.0
#include "field_names.h"

#include <utility>

#include "ao/core/error.h"
#include "ao/jobs/fields.h"

namespace ao::cli {

namespace {

namespace f = ao::fields;

// One row per field of fields::kAll (tests/cli/field_names_test.cpp checks that none is missing).
constexpr std::pair<std::string_view, std::string_view> kOptions[] = {
    {f::kCameraWidth, "--width"},
    {f::kCameraHeight, "--height"},
    {f::kCameraFov, "--fov"},
    {f::kCameraEye, "--eye"},
    {f::kCameraTarget, "--target"},
    {f::kCameraUp, "--up"},
    {f::kFalloffMembership, "--membership"},
    {f::kFalloffRadius, "--radius"},
    {f::kFalloffRadiusFraction, "--radius-fraction"},
    {f::kFalloffTau, "--tau"},
    {f::kNormal, "--normal"},
    {f::kDevice, "--device"},
    {f::kRenderScene, "a scene"},
    {f::kRenderGBufferFile, "--gbuffer-in"},
    {f::kRenderMethod, "--method"},
    {f::kRenderParams, "-p"},
    {f::kRenderSamples, "--spp"},
    {f::kRenderTargetError, "--target-error"},
    {f::kRenderSun, "--sun"},
    {f::kRenderAoMap, "--ao-map"},
    {f::kRenderVisibility, "-o"},
    {f::kRenderShaded, "--shaded"},
    {f::kRenderGBufferOut, "--gbuffer-out"},
    {f::kRenderExtras, "--extras"},
    {f::kRenderPngBits, "--png-bits"},
    {f::kRenderProvenance, "--provenance"},
    {f::kBakeMethod, "--method"},
    {f::kBakeSize, "--size"},
    {f::kBakeUvSet, "--uv-set"},
    {f::kBakePadding, "--padding"},
    {f::kBakeDenoise, "--denoise"},
    {f::kBakeMembership, "--membership"},
    {f::kBakeTexelSampling, "--texel-sampling"},
    {f::kBakeMaxDistance, "--max-distance"},
    {f::kBakeHigh, "--high"},
    {f::kBakeCage, "--cage"},
    {f::kBakeCageExtrusion, "--cage-extrusion"},
    {f::kBakeMaxFront, "--max-front"},
    {f::kBakeMaxBack, "--max-back"},
    {f::kBakeOccluders, "--occluder"},
    {f::kBakeFloor, "--floor"},
    {f::kBakeGroups, "--group"},
    {f::kBakeSelfOcclusion, "--self-occlusion"},
    {f::kBakeMatchByName, "--match-by-name"},
    {f::kBakeOrm, "--orm"},
    {f::kBakeReference, "--reference"},
    {f::kBakeOutDir, "--out-dir"},
    {f::kBakeMap, "-o"},
    {f::kBakeBentNormals, "--bent-normals"},
    {f::kBakeThickness, "--thickness"},
    {f::kBakeCavity, "--cavity"},
    {f::kBakeBentNormalSpace, "--bent-normals-space"},
    {f::kBakeThicknessDistance, "--thickness-distance"},
    {f::kBakeCavityDistance, "--cavity-distance"},
    {f::kBakePerVertex, "--per-vertex"},
    {f::kBakeGltf, "--gltf"},
    {f::kBakeMissMask, "--miss-mask"},
    {f::kBakePngBits, "--png-bits"},
    {f::kBakeProvenance, "--provenance"},
    {f::kPointsPoints, "the points"},
    {f::kPointsNormals, "the normals"},
    {f::kCompareMethods, "--methods"},
    {f::kCompareParams, "--param"},
    {f::kCompareReferences, "--reference"},
    {f::kCompareCommonReference, "--common-reference"},
    {f::kCompareSppReference, "--reference-samples"},
    {f::kCompareSweep, "--sweep"},
    {f::kCompareOutDir, "--out-dir"},
    {f::kTuneScenes, "--scenes"},
    {f::kTuneFit, "--fit"},
    {f::kTuneSppReference, "--reference-samples"},
    {f::kTuneOutput, "-o"},
};

}  // namespace

std::string option_name(std::string_view field) {
  for (const auto& [name, option] : kOptions)
    if (name == field) return std::string(option);
  return {};
}

std::string in_option_words(const std::string& text) { return name_fields(text, option_name); }

}  // namespace ao::cli
