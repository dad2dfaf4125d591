// SPDX-License-Identifier: Apache-2.0
// The request fields the job layer's errors name. An error marks them with field() (core/error.h),
// so that its text says "BakeRequest::padding must be in [0, 1024] texels, got 2000" to a library
// caller while the command line and the Python module each show their own name for the field
// ("--padding", "padding"), from a table of their own that covers every field listed here
// (src/cli/field_names.cpp, python/src/field_names.cpp).
#pragma once

#include <string_view>

namespace ao::fields {

// The camera and falloff every scene job takes (jobs/inputs.h).
inline constexpr std::string_view kCameraWidth = "CameraRequest::width";
inline constexpr std::string_view kCameraHeight = "CameraRequest::height";
inline constexpr std::string_view kCameraFov = "CameraRequest::fov";
inline constexpr std::string_view kCameraEye = "CameraRequest::eye";
inline constexpr std::string_view kCameraTarget = "CameraRequest::target";
inline constexpr std::string_view kCameraUp = "CameraRequest::up";
inline constexpr std::string_view kFalloffMembership = "FalloffRequest::membership";
inline constexpr std::string_view kFalloffRadius = "FalloffRequest::radius";
inline constexpr std::string_view kFalloffRadiusFraction = "FalloffRequest::radius_fraction";
inline constexpr std::string_view kFalloffTau = "FalloffRequest::tau";
inline constexpr std::string_view kNormal = "GBufferOptions::normal";  ///< The normal a scene's G-buffer is rendered with.
inline constexpr std::string_view kDevice = "RenderRequest::device";  ///< Where a method runs (also CompareSettings::device).

// Render (jobs/render.h).
inline constexpr std::string_view kRenderScene = "RenderRequest::scene";
inline constexpr std::string_view kRenderGBufferFile = "RenderRequest::gbuffer_file";
inline constexpr std::string_view kRenderMethod = "RenderRequest::method";
inline constexpr std::string_view kRenderParams = "RenderRequest::params";
inline constexpr std::string_view kRenderSamples = "RenderRequest::samples";
inline constexpr std::string_view kRenderTargetError = "RenderRequest::target_error";
inline constexpr std::string_view kRenderSun = "RenderRequest::sun";
inline constexpr std::string_view kRenderAoMap = "RenderRequest::ao_map";
inline constexpr std::string_view kRenderVisibility = "RenderRequest::outputs.visibility";
inline constexpr std::string_view kRenderShaded = "RenderRequest::outputs.shaded";
inline constexpr std::string_view kRenderGBufferOut = "RenderRequest::outputs.gbuffer";
inline constexpr std::string_view kRenderExtras = "RenderRequest::outputs.extras";
inline constexpr std::string_view kRenderPngBits = "RenderRequest::outputs.png_bits";
inline constexpr std::string_view kRenderProvenance = "RenderRequest::outputs.provenance";

// Bake (jobs/bake.h).
inline constexpr std::string_view kBakeMethod = "BakeRequest::method";
inline constexpr std::string_view kBakeSize = "BakeRequest::size";
inline constexpr std::string_view kBakeUvSet = "BakeRequest::uv_set";
inline constexpr std::string_view kBakePadding = "BakeRequest::padding";
inline constexpr std::string_view kBakeDenoise = "BakeRequest::denoise";
inline constexpr std::string_view kBakeMembership = "BakeRequest::raytraced.membership";
inline constexpr std::string_view kBakeTexelSampling = "BakeRequest::raytraced.texel_sampling";
inline constexpr std::string_view kBakeMaxDistance = "BakeRequest::raytraced.max_distance";
inline constexpr std::string_view kBakeHigh = "BakeRequest::high";
inline constexpr std::string_view kBakeCage = "BakeRequest::cage";
inline constexpr std::string_view kBakeCageExtrusion = "BakeRequest::high_to_low.cage_extrusion";
inline constexpr std::string_view kBakeMaxFront = "BakeRequest::high_to_low.max_front";
inline constexpr std::string_view kBakeMaxBack = "BakeRequest::high_to_low.max_back";
inline constexpr std::string_view kBakeOccluders = "BakeRequest::occluders";
inline constexpr std::string_view kBakeFloor = "BakeRequest::floor";
inline constexpr std::string_view kBakeGroups = "BakeRequest::groups";
inline constexpr std::string_view kBakeSelfOcclusion = "BakeRequest::self_occlusion";
inline constexpr std::string_view kBakeMatchByName = "BakeRequest::match_by_name";
inline constexpr std::string_view kBakeOrm = "BakeRequest::orm";
inline constexpr std::string_view kBakeReference = "BakeRequest::reference";
inline constexpr std::string_view kBakeOutDir = "BakeRequest::out_dir";
inline constexpr std::string_view kBakeMap = "BakeRequest::outputs.map";
inline constexpr std::string_view kBakeBentNormals = "BakeRequest::outputs.bent_normals";
inline constexpr std::string_view kBakeThickness = "BakeRequest::outputs.thickness";
inline constexpr std::string_view kBakeCavity = "BakeRequest::outputs.cavity";
inline constexpr std::string_view kBakeBentNormalSpace = "BakeRequest::bent_normal_space";
inline constexpr std::string_view kBakeThicknessDistance = "BakeRequest::thickness_distance";
inline constexpr std::string_view kBakeCavityDistance = "BakeRequest::cavity_distance";
inline constexpr std::string_view kBakePerVertex = "BakeRequest::outputs.per_vertex";
inline constexpr std::string_view kBakeGltf = "BakeRequest::outputs.gltf";
inline constexpr std::string_view kBakeMissMask = "BakeRequest::outputs.miss_mask";
inline constexpr std::string_view kBakePngBits = "BakeRequest::outputs.png_bits";
inline constexpr std::string_view kBakeProvenance = "BakeRequest::outputs.provenance";

// AO at points (jobs/points.h).
inline constexpr std::string_view kPointsPoints = "PointsRequest::points";
inline constexpr std::string_view kPointsNormals = "PointsRequest::normals";

// Compare and tune (jobs/compare.h, jobs/tune.h).
inline constexpr std::string_view kCompareMethods = "CompareSettings::methods";
inline constexpr std::string_view kCompareParams = "CompareSettings::params";
inline constexpr std::string_view kCompareReferences = "CompareSettings::references";
inline constexpr std::string_view kCompareCommonReference = "CompareSettings::common_reference";
inline constexpr std::string_view kCompareSppReference = "CompareSettings::spp_reference";
inline constexpr std::string_view kCompareSweep = "CompareSettings::sweep_key";
inline constexpr std::string_view kCompareOutDir = "CompareRequest::out_dir";
inline constexpr std::string_view kTuneScenes = "TuneRequest::scenes";
inline constexpr std::string_view kTuneFit = "TuneRequest::fit";
inline constexpr std::string_view kTuneSppReference = "TuneRequest::spp_reference";
inline constexpr std::string_view kTuneOutput = "TuneRequest::output";

/// Every field above, for the tables of other names to be checked complete.
inline constexpr std::string_view kAll[] = {
    kCameraWidth, kCameraHeight, kCameraFov, kCameraEye, kCameraTarget, kCameraUp, kFalloffMembership, kFalloffRadius,
    kFalloffRadiusFraction, kFalloffTau, kNormal, kDevice, kRenderScene, kRenderGBufferFile, kRenderMethod, kRenderParams,
    kRenderSamples, kRenderTargetError, kRenderSun, kRenderAoMap, kRenderVisibility, kRenderShaded, kRenderGBufferOut, kRenderExtras,
    kRenderPngBits, kRenderProvenance, kBakeMethod, kBakeSize, kBakeUvSet, kBakePadding, kBakeDenoise, kBakeMembership, kBakeTexelSampling,
    kBakeMaxDistance, kBakeHigh, kBakeCage, kBakeCageExtrusion, kBakeMaxFront, kBakeMaxBack, kBakeOccluders, kBakeFloor, kBakeGroups,
    kBakeSelfOcclusion, kBakeMatchByName, kBakeOrm, kBakeReference, kBakeOutDir, kBakeMap, kBakeBentNormals, kBakeThickness, kBakeCavity,
    kBakeBentNormalSpace, kBakeThicknessDistance, kBakeCavityDistance, kBakePerVertex,
    kBakeGltf, kBakeMissMask, kBakePngBits, kBakeProvenance, kPointsPoints, kPointsNormals, kCompareMethods, kCompareParams, kCompareReferences,
    kCompareCommonReference, kCompareSppReference, kCompareSweep, kCompareOutDir, kTuneScenes, kTuneFit, kTuneSppReference,
    kTuneOutput};

}  // namespace ao::fields
