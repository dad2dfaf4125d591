// SPDX-License-Identifier: Apache-2.0
// Generalized winding numbers of triangle meshes, based on A. Jacobson, L. Kavan and
// O. Sorkine-Hornung, "Robust inside-outside segmentation using generalized winding numbers"
// (SIGGRAPH 2013), evaluated with the hierarchy of G. Barill, N. Dickson, R. Schmidt, D. Levin and
// A. Jacobson, "Fast winding numbers for soups and clouds" (SIGGRAPH 2018).
//
// w(q) = (1 / 4 pi) sum over triangles of the signed solid angle the triangle subtends at q
// (Jacobson et al., sec. 3; each solid angle by Van Oosterom and Strackee's formula). A
// triangle counts positive seen from behind (its counter-clockwise front turned away from q), so
// w = 1 inside and 0 outside a closed mesh whose fronts face out, and w jumps by +1 when q crosses
// a triangle from its front to its back. For an open mesh w is smooth off the surface and is the
// measure of how much the surface wraps around q: about +1/2 just behind a sheet, -1/2 just in
// front of it, and 1 - (the solid angle of its holes seen from q) / 4 pi deep inside a closed mesh
// with small holes.
//
// Fast evaluation (Barill et al., sec. 3-4): a bounding volume hierarchy over the triangles; a node
// whose centre p~ is farther from q than beta times its radius is replaced by the Taylor expansion
// of its dipole field about p~ (the three terms of their far-field expansion: the field, its
// gradient and its Hessian at p~, against the triangles' exact area integrals of 1, p - p~ and
// (p - p~)(p - p~)^T); nearer nodes are opened, and leaves are summed exactly.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "ao/core/math.h"

namespace ao {

/// The generalized winding number field of one triangle mesh (or soup), ready for fast queries.
/// Immutable after construction; queries may run concurrently.
class WindingNumber {
 public:
  WindingNumber() = default;
  /// Over the triangles (indices[3t], indices[3t + 1], indices[3t + 2]) of `positions`, counter-
  /// clockwise seen from the front. Zero-area triangles add nothing. `beta` > 1: how far (in node
  /// radii) a node must be for its expansion to stand for it; Barill et al. use 2 (a relative
  /// truncation error of about (1/beta)^3 per node; measured against the exact sum in the tests).
  WindingNumber(std::span<const Vec3> positions, std::span<const std::uint32_t> indices, double beta = 2.0);

  /// w(q), fast (hierarchical).
  double operator()(Vec3 q) const;
  /// w(q) summed exactly over every triangle (O(triangles); for tests and small meshes).
  double exact(Vec3 q) const;
  /// Distance from q to the nearest triangle, positive behind it (its normal turned away from q),
  /// negative in front, 0 in its plane; +infinity for an empty mesh. Where w is near 0 (a point
  /// that sees as much of the mesh's fronts as of its backs) this tells the side of the part of
  /// the mesh nearest to q. Branch and bound over the same hierarchy.
  double signed_distance(Vec3 q) const;
  /// The first triangle along the ray o + t d, t in (t_min, t_max] (d need not be unit: t is in
  /// its lengths): its t, and +1 when the ray meets it from behind (its counter-clockwise front
  /// turned away from o), -1 from the front. t = +infinity, side 0 when it meets none. Both sides
  /// of every triangle are hit (Moller and Trumbore's test) and the hierarchy's boxes are the
  /// bound (a sheet's own thickness for the cone method's slabs, which side of it a point sees).
  struct Hit {
    float t;
    int side;
  };
  Hit first_hit(Vec3 o, Vec3 d, float t_min, float t_max) const;
  /// Number of triangles.
  std::size_t size() const { return tris_.size(); }

 private:
  struct Tri {
    Vec3 a, b, c;
  };
  struct Node {
    Vec3 centre;                    // area-weighted centroid p~ of its triangles
    float radius = 0;               // largest distance from p~ to a vertex of its triangles
    Vec3 t1;                        // sum of area x unit normal (first order)
    std::array<float, 9> t2{};      // sum of the integral of (p - p~) n^T, row-major (second order)
    std::array<float, 18> t3{};     // sum of n_j x the integral of (p - p~)_k (p - p~)_l, j x (k <= l) (third order)
    Vec3 lo, hi;                    // box of its triangles (the nearest-triangle search's bound)
    std::uint32_t first = 0, count = 0;  // leaf: triangles [first, first + count)
    std::uint32_t left = 0, right = 0;   // inner node: children (count == 0)
  };
  std::uint32_t build(std::vector<std::uint32_t>& order, std::uint32_t first, std::uint32_t count, const std::vector<Tri>& tris,
                      const std::vector<Vec3>& centroid, const std::vector<float>& area);
  static double solid_angle(const Tri& t, Vec3 q);
  static double solid_angle_float(const Tri& t, Vec3 q);

  std::vector<Tri> tris_;
  std::vector<Node> nodes_;
  double beta2_ = 4.0;  // beta^2
};

}  // namespace ao
