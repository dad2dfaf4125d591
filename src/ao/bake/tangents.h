// SPDX-License-Identifier: Apache-2.0
// Tangent frames of a mesh's UV layout as MikkTSpace defines them (Mikkelsen 2008, "Simulation of
// wrinkled surfaces revisited"; the definition Blender, glTF and the game engines share), so that
// a tangent-space map baked here decodes to the same direction in any of them; and the change of
// a world-space direction into the tangent space of a texel.
#pragma once

#include <cstdint>
#include <vector>

#include "ao/bake/texel_coverage.h"
#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/scene/mesh.h"

namespace ao {

/// The tangent of one triangle corner: unit `t`, perpendicular to the corner's vertex normal, and
/// the bitangent's sign (+1 or -1): bitangent = sign * cross(normal, t).
struct CornerTangent {
  Vec3 t;
  float sign = 1.0f;
};

/// MikkTSpace tangents of every corner of `m` (3 per triangle, in index order), from its
/// positions, vertex normals and UVs (both required). Per triangle, the direction of increasing u
/// in the triangle's plane (its sign flipped where the UV triangle is mirrored); per corner, the
/// sum of that direction projected into the plane of the corner's vertex normal over the
/// triangles that share the vertex, are joined to it through edges at the vertex and are mirrored
/// alike, each weighted by its angle at the vertex (measured in the normal's plane), normalised.
/// MikkTSpace's default angular threshold (180 degrees) never splits such a group, so none is
/// split here. Deviation: a triangle of zero UV area adds nothing to a group (MikkTSpace lets it
/// join any group); a corner whose sum is zero gets a direction perpendicular to its normal.
std::vector<CornerTangent> mikktspace_tangents(const Mesh& m);

/// The tangent frame at the centre of each covered texel of `cov` (computed on `scene`, whose
/// meshes with UVs have normals; `tangents[i]` = mikktspace_tangents(scene.meshes[i])): the
/// corner tangents and normals interpolated (not normalised, as a MikkTSpace shader interpolates
/// them) at the centre, in the texel's fragment whose UV triangle holds the centre (else its
/// largest fragment, the centre clamped into that triangle), and the sign of that triangle.
struct TexelFrames {
  Image<Vec3> t, n;
  Image<float> sign;
};
TexelFrames texel_frames(const Scene& scene, const TexelCoverage& cov, const std::vector<std::vector<CornerTangent>>& tangents);

/// The world-space direction `w` in the texel's tangent space: the unit (x, y, z) with
/// normalize(x t + y b + z n) = w / |w|, b = sign * cross(n, t): the inverse of what a MikkTSpace
/// shader does with a tangent-space normal. (0, 0, 1) where the frame is singular or w is zero.
Vec3 to_tangent_space(Vec3 w, Vec3 t, Vec3 n, float sign);

}  // namespace ao
