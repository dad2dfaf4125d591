// SPDX-License-Identifier: Apache-2.0
// Writes the open test meshes of the cone method's open-surface voxelization
// (tests/support/open_sheets.h) and closed meshes of the same sizes, each on a ground quad, as OBJ
// files for `ao compare`, with a camera that frames the object (docs/methods/cone.md, "Open meshes"):
//   ao_open_sheets /tmp/open-sheets
//   ao compare /tmp/open-sheets/arch.obj --camera /tmp/open-sheets/arch.camera.json --methods cone
// Objects: arch (a bent sheet with holes), bowl (half a sphere shell), open-box (a box without its
// top), mask, dome (with a window), terrain, tablecloth, leaf, gutter, the closed box, sphere and
// torus, a closed plate leaning on the ground (the leaf's wedge under a closed occluder), and the
// gutter (walls 0.03 and 0.005 thick) and the bowl as closed shells. The ground is a quad of twice
// the object's diagonal under it, and the camera looks at the object from the front right and
// above, as tests/methods/cone_test.cpp does.
// With a second argument, the folder of the shared meshes, also ChineseDragon-10kv and elephant
// opened as scans come (tests/support/open_sheets.h: the bottom 10% cut off, -cut.obj; holes of 3%
// of the diagonal punched, -holes.obj), alone:
//   ao_open_sheets /tmp/open-sheets ../shared/data/meshes
//   ao compare /tmp/open-sheets/elephant-cut.obj --methods cone
// Write them outside the repository.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ao/io/camera_json.h"
#include "ao/io/mesh_io.h"
#include "ao/scene/mesh.h"
#include "ao/scene/procedural.h"
#include "support/open_sheets.h"

namespace {

// A closed plate as wide as half the leaf (0.35), 0.03 thick and 1.2 long, leaning at the leaf's fold
// angle (25 degrees) on one long edge: the narrow wedge the leaf's half makes with the ground, under
// a closed occluder.
ao::Mesh make_leaning_plate() {
  ao::Mesh m = ao::make_box({0.0f, 0.0f, -0.6f}, {0.35f, 0.03f, 0.6f});
  const float angle = 25.0f * ao::test::kPi / 180.0f;  // about z, through the edge at the origin
  const float c = std::cos(angle), s = std::sin(angle);
  const auto turn = [&](ao::Vec3 v) { return ao::Vec3{c * v.x - s * v.y, s * v.x + c * v.y, v.z}; };
  for (ao::Vec3& p : m.positions) p = turn(p);
  for (ao::Vec3& n : m.normals) n = turn(n);
  return m;
}

// The suite's gutter as a closed shell: walls `wall` thick outside the open gutter's radius of 0.2,
// closed along its rims and at its ends. What the methods make of the same shape as a solid.
ao::Mesh make_closed_gutter(float wall) {
  constexpr int kAround = 48, kAlong = 96;
  constexpr float kInner = 0.2f, kLength = 2.0f;
  const float outer_radius = kInner + wall;
  ao::Mesh m;
  const auto ring = [&](float radius, int j) {
    const auto first = static_cast<std::uint32_t>(m.positions.size());
    const float z = kLength * (static_cast<float>(j) / kAlong - 0.5f);
    for (int i = 0; i <= kAround; ++i) {
      const float a = ao::test::kPi * (1.0f + static_cast<float>(i) / kAround);  // from -x under the axis to +x
      m.positions.push_back({radius * std::cos(a), outer_radius + radius * std::sin(a), z});
    }
    return first;
  };
  std::vector<std::uint32_t> inner, outer;
  for (int j = 0; j <= kAlong; ++j) inner.push_back(ring(kInner, j)), outer.push_back(ring(outer_radius, j));
  const auto quad = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) { m.indices.insert(m.indices.end(), {a, b, c, a, c, d}); };
  const auto in = static_cast<std::uint32_t>(kAround);
  for (int j = 0; j < kAlong; ++j) {
    for (std::uint32_t i = 0; i < in; ++i) {
      quad(inner[j] + i, inner[j + 1] + i, inner[j + 1] + i + 1, inner[j] + i + 1);  // into the hollow
      quad(outer[j] + i, outer[j] + i + 1, outer[j + 1] + i + 1, outer[j + 1] + i);  // out
    }
    quad(inner[j], outer[j], outer[j + 1], inner[j + 1]);  // the rims
    quad(inner[j] + in, inner[j + 1] + in, outer[j + 1] + in, outer[j] + in);
  }
  for (std::uint32_t i = 0; i < in; ++i) {  // the ends, half annuli
    quad(inner[0] + i, inner[0] + i + 1, outer[0] + i + 1, outer[0] + i);
    quad(inner[kAlong] + i, outer[kAlong] + i, outer[kAlong] + i + 1, inner[kAlong] + i + 1);
  }
  return m;
}

// The suite's bowl as a closed shell: walls 0.03 thick outside the open bowl's radius of 1, closed
// along its rim, its lowest point on y = 0. The bowl's closed counterpart, as the closed gutter is
// the gutter's.
ao::Mesh make_closed_bowl() {
  constexpr int kAround = 96, kDown = 24;  // the open bowl's segments; rings from the rim to the pole
  constexpr float kInner = 1.0f, kOuter = 1.03f;
  const ao::Vec3 centre{0.0f, kOuter, 0.0f};
  ao::Mesh m;
  // Ring j (0: the rim, on the centre's level) of radius r, kAround vertices; j = kDown is the pole.
  const auto ring = [&](float r, int j) {
    const auto first = static_cast<std::uint32_t>(m.positions.size());
    const float e = 0.5f * ao::test::kPi * static_cast<float>(j) / kDown;  // below the rim
    if (j == kDown) {
      m.positions.push_back({0.0f, kOuter - r, 0.0f});
      return first;
    }
    for (int i = 0; i < kAround; ++i) {
      const float a = 2.0f * ao::test::kPi * static_cast<float>(i) / kAround;
      m.positions.push_back({r * std::cos(e) * std::cos(a), kOuter - r * std::sin(e), r * std::cos(e) * std::sin(a)});
    }
    return first;
  };
  // A triangle wound so that its normal points along `out` (away from the solid).
  const auto triangle = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, ao::Vec3 out) {
    const ao::Vec3 pa = m.positions[a], pb = m.positions[b], pc = m.positions[c];
    if (ao::dot(ao::cross(pb - pa, pc - pa), out) < 0) std::swap(b, c);
    m.indices.insert(m.indices.end(), {a, b, c});
  };
  std::vector<std::uint32_t> inner, outer;
  for (int j = 0; j <= kDown; ++j) inner.push_back(ring(kInner, j)), outer.push_back(ring(kOuter, j));
  const auto at = [](std::uint32_t first, int i) { return first + static_cast<std::uint32_t>(i % kAround); };
  for (int j = 0; j < kDown; ++j)
    for (int i = 0; i < kAround; ++i)
      for (const auto& [rings, sign] : {std::pair{&outer, 1.0f}, std::pair{&inner, -1.0f}}) {
        const std::uint32_t a = at((*rings)[j], i), b = at((*rings)[j], i + 1);
        const ao::Vec3 out = sign * (m.positions[a] - centre);
        if (j + 1 == kDown) {
          triangle(a, b, (*rings)[kDown], out);
        } else {
          triangle(a, b, at((*rings)[j + 1], i + 1), out);
          triangle(a, at((*rings)[j + 1], i + 1), at((*rings)[j + 1], i), out);
        }
      }
  for (int i = 0; i < kAround; ++i) {  // the rim, an annulus facing up
    triangle(at(inner[0], i), at(outer[0], i), at(outer[0], i + 1), {0, 1, 0});
    triangle(at(inner[0], i), at(outer[0], i + 1), at(inner[0], i + 1), {0, 1, 0});
  }
  return m;
}

// One material per mesh (named after it, in a .mtl beside the file): the loader keeps meshes with
// different materials apart, and each is classified on its own (closed, solid with holes, sheet).
// Each vertex's normal goes with it (vn): without them the loader joins a box's coincident corner
// vertices and smooths its normals across the edges, and the box is shaded as a rounded one.
void write_obj(const std::filesystem::path& path, const std::vector<std::pair<std::string, ao::Mesh>>& meshes) {
  std::filesystem::path mtl = path;
  mtl.replace_extension(".mtl");
  std::ofstream materials(mtl);
  for (const auto& [name, m] : meshes) materials << "newmtl " << name << "\nKd " << m.albedo.x << ' ' << m.albedo.y << ' ' << m.albedo.z << "\n";
  std::ofstream out(path);
  out.precision(9);
  out << "mtllib " << mtl.filename().string() << "\n";
  std::size_t base = 1;
  for (const auto& [name, mesh] : meshes) {
    ao::Mesh m = mesh;
    if (m.normals.empty()) ao::generate_normals(m);
    out << "o " << name << "\nusemtl " << name << "\n";
    for (const ao::Vec3& p : m.positions) out << "v " << p.x << ' ' << p.y << ' ' << p.z << "\n";
    for (const ao::Vec3& n : m.normals) out << "vn " << n.x << ' ' << n.y << ' ' << n.z << "\n";
    const auto corner = [&](std::size_t i) { return std::to_string(base + i) + "//" + std::to_string(base + i); };
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
      out << "f " << corner(m.indices[3 * t]) << ' ' << corner(m.indices[3 * t + 1]) << ' ' << corner(m.indices[3 * t + 2]) << "\n";
    base += m.positions.size();
  }
  if (!out || !materials) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && argc != 3) {
    std::cerr << "usage: ao_open_sheets OUTPUT_FOLDER [SHARED_MESHES_FOLDER]\n";
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const std::vector<std::pair<std::string, ao::Mesh>> objects{
        {"arch", ao::test::make_holed_arch()},
        {"bowl", ao::test::make_bowl()},
        {"open-box", ao::test::make_open_box()},
        {"mask", ao::test::make_mask()},
        {"dome", ao::test::make_dome()},
        {"terrain", ao::test::make_terrain()},
        {"tablecloth", ao::test::make_tablecloth()},
        {"leaf", ao::test::make_leaf()},
        {"gutter", ao::test::make_gutter()},
        {"box", ao::make_box({-0.9f, 0.0f, -0.7f}, {0.9f, 1.0f, 0.7f})},
        {"sphere", ao::make_sphere({0, 1, 0}, 1.0f, 96, 48)},
        {"torus", ao::make_torus({0, 0.35f, 0}, 1.0f, 0.35f, 64, 24)},
        {"head", ao::test::make_head()},
        {"plate", make_leaning_plate()},
        {"closed-gutter", make_closed_gutter(0.03f)},
        {"thin-closed-gutter", make_closed_gutter(0.005f)},
        {"closed-bowl", make_closed_bowl()},
    };
    for (const auto& [name, mesh] : objects) {
      write_obj(dir / (name + ".obj"), {{name, mesh}, {"ground", ao::test::ground_under(mesh, {0.75f, 0.73f, 0.70f})}});
      std::ofstream camera(dir / (name + ".camera.json"));
      camera << ao::camera_to_json(ao::frame_bounds(mesh.bounds(), {1.0f, 0.8f, 1.3f}, 40.0f, 640, 360)).dump() << "\n";
      if (!camera) throw std::runtime_error("cannot write " + (dir / (name + ".camera.json")).string());
      std::cout << (dir / (name + ".obj")).string() << "\n";
    }
    if (argc == 3) {
      for (const std::string name : {"ChineseDragon-10kv", "elephant"}) {
        const ao::Mesh closed = ao::load_scene_file(std::filesystem::path(argv[2]) / (name + ".off")).meshes.at(0);
        for (const auto& [suffix, open] : {std::pair{"-cut", ao::test::cut_base(closed, 0.1f)}, std::pair{"-holes", ao::test::punch_holes(closed, 0.03f)}}) {
          write_obj(dir / (name + suffix + ".obj"), {{name, open}});
          std::cout << (dir / (name + suffix + ".obj")).string() << "\n";
        }
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "ao_open_sheets: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
