// SPDX-License-Identifier: Apache-2.0
// Bake groups: which meshes occlude which. A group's meshes are baked with only that group's
// meshes (plus the shared occluders: --occluder files, the floor) in the scene, so meshes of
// different groups do not darken each other, as Substance's and Marmoset's bake groups do. Groups
// come from mesh names (Substance's `_low` / `_high` suffixes), from explicit lists, or one group
// per mesh (self-occlusion only).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "ao/bake/bake_result.h"
#include "ao/bake/texel_coverage.h"
#include "ao/scene/mesh.h"

namespace ao {

/// One bake group: indices of the baked (low) meshes and, for high-to-low, of the high meshes
/// they are baked from.
struct BakeGroup {
  std::string name;
  std::vector<std::size_t> meshes;
  std::vector<std::size_t> high;
};

/// The name with a trailing `_low` or `_high` (any case) removed: the key of match-by-name.
std::string bake_group_key(const std::string& mesh_name);

/// Match by name: one group per key of the low meshes, holding the low meshes with that key and
/// the high meshes with the same key. A low mesh whose key no high mesh has is an InputError
/// naming it (it would bake from nothing); unmatched high meshes are returned in `unused_high`.
std::vector<BakeGroup> groups_by_name(const Scene& low, const Scene& high, std::vector<std::string>* unused_high = nullptr);

/// Explicit groups: each entry of `lists` is a list of mesh names forming one group; meshes not
/// named form one more group together. A name that is no mesh, or that is named twice, is an
/// InputError naming it.
std::vector<BakeGroup> groups_from_lists(const Scene& scene, const std::vector<std::vector<std::string>>& lists);

/// One group per mesh: each mesh occluded only by itself.
std::vector<BakeGroup> groups_per_mesh(const Scene& scene);

/// A ground plane under a model with bounds `model` (y up): a slab whose top is at the model's
/// lowest y, 20 model diagonals wide, so a point of the model sees it as the ground to within
/// atan(1/20) ~ 3 degrees of the horizon. Named "floor", no UVs.
Mesh make_floor_occluder(const Bounds3& model);

/// The scene of one group: its meshes of `scene`, in order, followed by `occluders` (whose UVs
/// are dropped so they are not baked).
Scene group_scene(const Scene& scene, const BakeGroup& group, const std::vector<Mesh>& occluders);

/// Bakes each group with `bake(group_scene, coverage)` (coverage computed on the group scene for a
/// `width` x `height` map) and merges the maps: each texel is the area-weighted mean of the groups covering it
/// (one group, except where charts of different groups overlap). Groups whose meshes have no UVs
/// are skipped. Rays, fragments and missed texels are summed; warnings are concatenated.
/// `scene_coverage`: compute_texel_coverage(scene, width, height) when the caller has it already
/// (or null): a group of all of scene's meshes, in order, has the same coverage (the occluders
/// carry no UVs), so it is not computed again.
BakeResult bake_groups(const Scene& scene, const std::vector<BakeGroup>& groups, const std::vector<Mesh>& occluders, int width, int height,
                       const std::function<BakeResult(const Scene&, const TexelCoverage&, const BakeGroup&)>& bake,
                       const TexelCoverage* scene_coverage = nullptr);

}  // namespace ao
