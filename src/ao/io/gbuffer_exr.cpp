// SPDX-License-Identifier: Apache-2.0
#include "ao/io/gbuffer_exr.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfVecAttribute.h>

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/exr_common_internal.h"
#include "ao/simd/depth_plane.h"

namespace ao {

namespace fs = std::filesystem;
using namespace io_detail;

static_assert(sizeof(Vec3) == 3 * sizeof(float), "Vec3 images are handed to OpenEXR as interleaved floats");

namespace {

constexpr const char* kFovAttribute = "ao:verticalFov";
constexpr const char* kEyeAttribute = "ao:eye";
constexpr const char* kTargetAttribute = "ao:target";
constexpr const char* kUpAttribute = "ao:up";
// Albedo of pixels whose file has no albedo channels: a mid-light grey, neither black (which would
// remove the bounce term of ambient transfer) nor white.
constexpr float kDefaultAlbedo = 0.8f;

Imath::V3f to_imath(Vec3 v) { return {v.x, v.y, v.z}; }
Vec3 from_imath(const Imath::V3f& v) { return {v.x, v.y, v.z}; }

// OpenEXR's worldToCamera maps world points to a left-handed camera space looking down +z
// (RenderMan's), and Imath multiplies row vectors (p' = p * M, translation in the last row).
// Ours looks down -z, so its third axis is our basis().z negated.
Imath::M44f world_to_camera_matrix(const Camera& camera) {
  const Frame f = camera.basis();
  const Vec3 axes[3] = {f.t, f.b, -f.n};
  Imath::M44f m;  // identity
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) m[i][j] = axes[j][i];
    m[3][j] = -dot(camera.eye, axes[j]);
  }
  return m;
}

// Inverse of world_to_camera_matrix for any rigid (or uniformly scaled) matrix from a renderer.
bool camera_from_matrix(const Imath::M44f& world_to_camera, Camera& camera) {
  const Imath::M44f to_world = world_to_camera.inverse();  // identity if singular: caught below
  const Vec3 eye{to_world[3][0], to_world[3][1], to_world[3][2]};
  const Vec3 up{to_world[1][0], to_world[1][1], to_world[1][2]};
  const Vec3 forward{to_world[2][0], to_world[2][1], to_world[2][2]};
  if (!is_finite(eye) || !is_finite(up) || !is_finite(forward) || length(forward) <= 0) return false;
  camera.eye = eye;
  camera.target = eye + normalize(forward);
  camera.up = normalize(up);
  return true;
}

template <class T>
const T* find_attribute(const Imf::Header& header, const char* name) {
  return header.findTypedAttribute<T>(name);
}

std::string format_vec(Vec3 v) {
  std::ostringstream s;
  s << '(' << v.x << ", " << v.y << ", " << v.z << ')';
  return s.str();
}

[[noreturn]] void bad_pixel(const fs::path& path, int x, int y, const std::string& problem) {
  throw InputError(path.string() + ": pixel (" + std::to_string(x) + ", " + std::to_string(y) + "): " + problem);
}

std::string channel_list(const Imf::ChannelList& channels) {
  std::string names;
  int count = 0;
  for (auto it = channels.begin(); it != channels.end(); ++it, ++count) {
    if (count == 12) return names + ", ...";  // keep the error on one readable line
    if (!names.empty()) names += ", ";
    names += it.name();
  }
  return names.empty() ? "none" : names;
}

// Camera placement and fov from the header. Returns whether the placement was in the file.
bool read_camera(const Imf::Header& header, const fs::path& path, const GBufferReadOptions& opt, Camera& camera) {
  bool placed = false;
  const auto* eye = find_attribute<Imf::V3fAttribute>(header, kEyeAttribute);
  const auto* target = find_attribute<Imf::V3fAttribute>(header, kTargetAttribute);
  const auto* up = find_attribute<Imf::V3fAttribute>(header, kUpAttribute);
  if (eye && target && up) {
    camera.eye = from_imath(eye->value());
    camera.target = from_imath(target->value());
    camera.up = from_imath(up->value());
    placed = true;
  } else if (Imf::hasWorldToCamera(header)) {
    if (!camera_from_matrix(Imf::worldToCamera(header), camera))
      throw InputError(path.string() + ": worldToCamera attribute is not an invertible camera matrix");
    placed = true;
  } else {
    // No placement: world space is camera space.
    camera.eye = {0, 0, 0};
    camera.target = {0, 0, -1};
    camera.up = {0, 1, 0};
  }

  if (opt.vertical_fov_deg) {
    camera.vertical_fov_deg = *opt.vertical_fov_deg;
  } else if (const auto* f = find_attribute<Imf::FloatAttribute>(header, kFovAttribute)) {
    camera.vertical_fov_deg = f->value();
  } else if (const auto* d = find_attribute<Imf::DoubleAttribute>(header, kFovAttribute)) {
    camera.vertical_fov_deg = static_cast<float>(d->value());
  } else {
    throw InputError(path.string() + ": no camera field of view (attribute " + kFovAttribute +
                     "); pass the vertical field of view in degrees with --fov");
  }
  try {
    camera.validate();
  } catch (const InputError& e) {
    throw InputError(path.string() + ": " + e.what());
  }
  return placed;
}

// Every channel at full resolution, and the four no G-buffer can do without.
void check_channels(const Imf::ChannelList& channels, const fs::path& path) {
  for (auto it = channels.begin(); it != channels.end(); ++it)
    if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
      throw InputError(path.string() + ": channel '" + it.name() + "' is subsampled, which is not supported");
  std::string missing;
  for (const char* name : {"Z", "N.X", "N.Y", "N.Z"}) {
    if (channels.findChannel(name) != nullptr) continue;
    if (!missing.empty()) missing += ' ';
    missing += name;
  }
  if (!missing.empty())
    throw InputError(path.string() + ": missing G-buffer channels " + missing + " (the file has: " + channel_list(channels) +
                     "); at least Z and N.X N.Y N.Z are needed, see docs/gbuffer.md");
}

// The planes read from the file, one float or uint per pixel; pixels outside the data window keep
// their fills (background). The optional passes are empty when the file lacks them.
struct ExrPlanes {
  std::vector<float> z, nx, ny, nz, px, py, pz, ar, ag, ab, a, dr, dg, db;
  std::vector<std::uint32_t> id, primitive;
  bool has_p = false, has_albedo = false, has_direct = false, has_a = false, has_id = false, has_primitive = false;
};

ExrPlanes read_planes(Imf::InputFile& file, const ExrWindows& w, const fs::path& path) {
  const Imf::ChannelList& channels = file.header().channels();
  const auto has = [&](const char* name) { return channels.findChannel(name) != nullptr; };
  const std::size_t n = static_cast<std::size_t>(w.width) * w.height;
  ExrPlanes p;
  p.has_p = has("P.X") && has("P.Y") && has("P.Z");
  p.has_albedo = has("albedo.R") && has("albedo.G") && has("albedo.B");
  p.has_id = has("id");
  p.has_primitive = has("primid");
  p.has_a = has("A");
  const int direct_channels = int{has("direct.R")} + int{has("direct.G")} + int{has("direct.B")};
  if (direct_channels != 0 && direct_channels != 3)
    throw InputError(path.string() + ": the direct-light pass needs all of direct.R direct.G direct.B (the file has: " + channel_list(channels) + ")");
  p.has_direct = direct_channels == 3;
  p.z.assign(n, kInfinity), p.nx.assign(n, 0.0f), p.ny.assign(n, 0.0f), p.nz.assign(n, 0.0f);
  std::vector<ExrChannelTarget> targets = {{"Z", Imf::FLOAT, p.z.data()},
                                           {"N.X", Imf::FLOAT, p.nx.data()},
                                           {"N.Y", Imf::FLOAT, p.ny.data()},
                                           {"N.Z", Imf::FLOAT, p.nz.data()}};
  const auto add = [&](const char* name, std::vector<float>& plane) {
    plane.assign(n, 0.0f);
    targets.push_back({name, Imf::FLOAT, plane.data()});
  };
  if (p.has_p) add("P.X", p.px), add("P.Y", p.py), add("P.Z", p.pz);
  if (p.has_albedo) add("albedo.R", p.ar), add("albedo.G", p.ag), add("albedo.B", p.ab);
  if (p.has_direct) add("direct.R", p.dr), add("direct.G", p.dg), add("direct.B", p.db);
  if (p.has_a) add("A", p.a);
  if (p.has_id) {
    p.id.assign(n, 0u);
    targets.push_back({"id", Imf::UINT, p.id.data()});
  }
  if (p.has_primitive) {
    p.primitive.assign(n, 0u);
    targets.push_back({"primid", Imf::UINT, p.primitive.data()});
  }
  read_exr_channels(file, w, targets);
  return p;
}

// The G-buffer from the planes: covered pixels (A >= 0.5, or a finite depth nearer than the
// background's) checked and moved to camera space; every other pixel stays background.
GBuffer gbuffer_from_planes(const ExrPlanes& p, const Camera& camera, const GBufferReadOptions& opt, const fs::path& path) {
  GBuffer g(camera);
  const int width = camera.width, height = camera.height;
  if (p.has_direct) g.direct = Image<Vec3>(width, height);  // 0 where not covered
  if (p.has_primitive) g.primitive_id = Image<std::uint32_t>(width, height, 0u);
  const Frame basis = camera.basis();
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      const float depth = p.z[i];
      const bool covered = p.has_a ? p.a[i] >= 0.5f : (std::isfinite(depth) && depth > 0.0f && depth < opt.background_depth);
      if (!covered) continue;  // GBuffer(camera) already holds the background values
      if (!(std::isfinite(depth) && depth > 0.0f))
        bad_pixel(path, x, y, "covered (A >= 0.5) but depth Z = " + std::to_string(depth) + " is not finite and positive");

      Vec3 normal{p.nx[i], p.ny[i], p.nz[i]};
      Vec3 position = p.has_p ? Vec3{p.px[i], p.py[i], p.pz[i]} : camera.camera_direction(x + 0.5f, y + 0.5f) * depth;
      if (opt.world_space) {
        normal = basis.to_local(normal);
        if (p.has_p) position = camera.world_to_camera_point(position);
      }
      if (!is_finite(normal) || length(normal) <= 0.0f) bad_pixel(path, x, y, "normal N = " + format_vec(normal) + " is not a finite, non-zero vector");
      if (!is_finite(position)) bad_pixel(path, x, y, "position P = " + format_vec(position) + " is not finite");
      // The G-buffer's depth is -P.z (GBuffer::depth): the point must be in front of the camera.
      if (!(position.z < 0.0f)) bad_pixel(path, x, y, "position P = " + format_vec(position) + " is not in front of the camera (P.z must be < 0)");
      const std::uint32_t object = p.has_id ? p.id[i] : 1u;
      if (object == 0) bad_pixel(path, x, y, "covered but its id is 0, which marks background (surfaces have ids >= 1)");
      const Vec3 albedo = p.has_albedo ? Vec3{p.ar[i], p.ag[i], p.ab[i]} : Vec3{kDefaultAlbedo, kDefaultAlbedo, kDefaultAlbedo};
      if (!is_finite(albedo)) bad_pixel(path, x, y, "albedo = " + format_vec(albedo) + " is not finite");
      if (p.has_direct) {
        const Vec3 d{p.dr[i], p.dg[i], p.db[i]};
        if (!is_finite(d) || d.x < 0 || d.y < 0 || d.z < 0)
          bad_pixel(path, x, y, "direct radiance = " + format_vec(d) + " is not finite and >= 0");
        g.direct(x, y) = d;
      }

      g.position(x, y) = position;
      g.normal(x, y) = normalize(normal);  // passes are often filtered or stored as half: renormalise
      g.albedo(x, y) = albedo;
      g.object_id(x, y) = object;
      if (p.has_primitive) g.primitive_id(x, y) = p.primitive[i];
    }
  }
  return g;
}

GBuffer read_gbuffer(const fs::path& path, const GBufferReadOptions& opt) {
  Imf::InputFile file(path.c_str());
  const Imf::Header& header = file.header();
  const ExrWindows w = exr_windows(header, path);
  check_channels(header.channels(), path);

  Camera camera;
  camera.width = w.width;
  camera.height = w.height;
  const bool placed = read_camera(header, path, opt, camera);
  if (opt.world_space && !placed)
    throw InputError(path.string() + ": world-space passes need the camera placement (ao:eye/target/up or worldToCamera), "
                     "and the file has none");
  const ExrPlanes planes = read_planes(file, w, path);
  return gbuffer_from_planes(planes, camera, opt, path);
}

}  // namespace

void write_gbuffer_exr(const fs::path& path, const GBuffer& g, const GBufferWriteOptions& opt) {
  const int width = g.width(), height = g.height();
  const auto same_size = [&](const auto& image) { return image.width() == width && image.height() == height; };
  if (width < 1 || height < 1 || !same_size(g.position) || !same_size(g.normal) || !same_size(g.albedo) || !same_size(g.object_id) ||
      (!g.direct.empty() && !same_size(g.direct)) ||
      (!g.primitive_id.empty() && !same_size(g.primitive_id)))
    throw InputError(path.string() + ": G-buffer images do not all match the camera's " + std::to_string(width) + "x" +
                     std::to_string(height) + " pixels");

  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  if (opt.camera) {
    Imf::addWorldToCamera(header, world_to_camera_matrix(g.camera));
    header.insert(kFovAttribute, Imf::FloatAttribute(g.camera.vertical_fov_deg));
    header.insert(kEyeAttribute, Imf::V3fAttribute(to_imath(g.camera.eye)));
    header.insert(kTargetAttribute, Imf::V3fAttribute(to_imath(g.camera.target)));
    header.insert(kUpAttribute, Imf::V3fAttribute(to_imath(g.camera.up)));
  }

  // Depth and coverage are not stored in the G-buffer: Z is computed from the positions, and the
  // coverage becomes a float alpha (what compositors expect in A).
  const Image<float> depth = depth_plane(g);
  std::vector<float> alpha(g.object_id.size());
  for (std::size_t i = 0; i < alpha.size(); ++i) alpha[i] = g.covered(i) ? 1.0f : 0.0f;

  Imf::FrameBuffer frame;
  const std::size_t w = static_cast<std::size_t>(width);
  // OpenEXR's Slice takes a non-const pointer for reading and writing alike; writing only reads it.
  const auto insert = [&](const char* name, Imf::PixelType type, const void* base, std::size_t x_stride) {
    header.channels().insert(name, Imf::Channel(type));
    frame.insert(name, Imf::Slice(type, static_cast<char*>(const_cast<void*>(base)), x_stride, x_stride * w));
  };
  const auto insert_vec3 = [&](const char* x, const char* y, const char* z, const Image<Vec3>& image) {
    const float* base = reinterpret_cast<const float*>(image.data());
    insert(x, Imf::FLOAT, base, sizeof(Vec3));
    insert(y, Imf::FLOAT, base + 1, sizeof(Vec3));
    insert(z, Imf::FLOAT, base + 2, sizeof(Vec3));
  };
  Image<Vec3> world_position, world_normal;
  if (opt.world_space) {
    world_position = g.position, world_normal = g.normal;
    for (std::size_t i = 0; i < g.object_id.size(); ++i)
      if (g.covered(i))
        world_position[i] = g.camera.camera_to_world_point(g.position[i]), world_normal[i] = g.camera.camera_to_world_vector(g.normal[i]);
  }
  const Image<Vec3>& position = opt.world_space ? world_position : g.position;
  const Image<Vec3>& normal = opt.world_space ? world_normal : g.normal;
  if (opt.positions) insert_vec3("P.X", "P.Y", "P.Z", position);
  insert("Z", Imf::FLOAT, depth.data(), sizeof(float));
  insert_vec3("N.X", "N.Y", "N.Z", normal);
  if (opt.albedo) insert_vec3("albedo.R", "albedo.G", "albedo.B", g.albedo);
  if (opt.object_ids) insert("id", Imf::UINT, g.object_id.data(), sizeof(std::uint32_t));
  if (opt.primitive_ids && !g.primitive_id.empty()) insert("primid", Imf::UINT, g.primitive_id.data(), sizeof(std::uint32_t));
  if (opt.coverage) insert("A", Imf::FLOAT, alpha.data(), sizeof(float));
  if (opt.direct && !g.direct.empty()) insert_vec3("direct.R", "direct.G", "direct.B", g.direct);
  write_exr_atomically(path, header, frame);
}

GBuffer read_gbuffer_exr(const fs::path& path, const GBufferReadOptions& opt) {
  require_input_file(path);
  if (!is_exr_magic(read_magic(path, 4))) throw InputError(path.string() + ": not an OpenEXR file");
  return with_exr_errors(path, "not a readable OpenEXR file", [&] { return read_gbuffer(path, opt); });
}

}  // namespace ao
