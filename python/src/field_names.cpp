// SPDX-License-Identifier: Apache-2.0
#include "field_names.h"

#include "ao/jobs/fields.h"

namespace ao::python {

namespace {

namespace f = ao::fields;

// One row per field of fields::kAll (tests/python/test_errors.py checks that none is missing);
// "" where ao's Python functions have no argument for the field: the message keeps its library
// name, which says what the C++ request calls it.
constexpr std::pair<std::string_view, std::string_view> kKeywords[] = {
    {f::kCameraWidth, "camera.width"},
    {f::kCameraHeight, "camera.height"},
    {f::kCameraFov, "camera.fov"},
    {f::kCameraEye, "camera.eye"},
    {f::kCameraTarget, "camera.target"},
    {f::kCameraUp, "camera.up"},
    {f::kFalloffMembership, "membership"},
    {f::kFalloffRadius, "radius"},
    {f::kFalloffRadiusFraction, "radius_fraction"},
    {f::kFalloffTau, "tau"},
    {f::kNormal, "normal"},
    {f::kDevice, ""},
    {f::kRenderScene, "scene"},
    {f::kRenderGBufferFile, "gbuffer"},
    {f::kRenderMethod, "method"},
    {f::kRenderParams, "the method parameter"},
    {f::kRenderSamples, "spp"},
    {f::kRenderTargetError, "target_error"},
    {f::kRenderSun, ""},
    {f::kRenderAoMap, ""},
    {f::kRenderVisibility, "output"},
    {f::kRenderShaded, "shaded"},
    {f::kRenderGBufferOut, "gbuffer_output"},
    {f::kRenderExtras, "extras"},
    {f::kRenderPngBits, "png_bits"},
    {f::kRenderProvenance, "provenance"},
    {f::kBakeMethod, "method"},
    {f::kBakeSize, "size"},
    {f::kBakeUvSet, "uv_set"},
    {f::kBakePadding, "padding"},
    {f::kBakeDenoise, "denoise"},
    {f::kBakeMembership, "membership"},
    {f::kBakeTexelSampling, "texel_sampling"},
    {f::kBakeMaxDistance, "max_distance"},
    {f::kBakeHigh, "high"},
    {f::kBakeCage, "cage"},
    {f::kBakeCageExtrusion, "cage_extrusion"},
    {f::kBakeMaxFront, "max_front"},
    {f::kBakeMaxBack, "max_back"},
    {f::kBakeOccluders, ""},
    {f::kBakeFloor, ""},
    {f::kBakeGroups, ""},
    {f::kBakeSelfOcclusion, ""},
    {f::kBakeMatchByName, ""},
    {f::kBakeOrm, ""},
    {f::kBakeReference, ""},
    {f::kBakeOutDir, ""},
    {f::kBakeMap, "output"},
    {f::kBakeBentNormals, "bent_normals_output"},
    {f::kBakeThickness, "thickness_output"},
    {f::kBakeCavity, "cavity_output"},
    {f::kBakeBentNormalSpace, "bent_normals_space"},
    {f::kBakeThicknessDistance, "thickness_distance"},
    {f::kBakeCavityDistance, "cavity_distance"},
    {f::kBakePerVertex, "per_vertex_output"},
    {f::kBakeGltf, "gltf_output"},
    {f::kBakeMissMask, ""},
    {f::kBakePngBits, "png_bits"},
    {f::kBakeProvenance, "provenance"},
    {f::kPointsPoints, "points"},
    {f::kPointsNormals, "normals"},
    {f::kCompareMethods, "methods"},
    {f::kCompareParams, "params"},
    {f::kCompareReferences, "reference"},
    {f::kCompareCommonReference, "common_reference"},
    {f::kCompareSppReference, "spp_reference"},
    {f::kCompareSweep, "sweep"},
    {f::kCompareOutDir, "out_dir"},
    {f::kTuneScenes, ""},
    {f::kTuneFit, ""},
    {f::kTuneSppReference, ""},
    {f::kTuneOutput, ""},
};

}  // namespace

std::string keyword_name(std::string_view field) {
  for (const auto& [name, keyword] : kKeywords)
    if (name == field) return std::string(keyword);
  return {};
}

std::vector<std::pair<std::string, std::string>> keyword_table() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [name, keyword] : kKeywords) out.emplace_back(name, keyword);
  return out;
}

}  // namespace ao::python
