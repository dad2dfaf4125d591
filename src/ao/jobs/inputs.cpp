// SPDX-License-Identifier: Apache-2.0
#include "ao/jobs/inputs.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/io/camera_json.h"
#include "ao/jobs/fields.h"
#include "ao/reference/ray_scene.h"
#include "ao/scene/procedural.h"

namespace ao {

namespace {

namespace fs = std::filesystem;

// A lone word that is not a file names a built-in scene (an unknown one gets the list of names).
bool names_builtin_scene(const std::vector<std::string>& args) {
  if (args.size() != 1) return false;
  const fs::path first(args[0]);
  return !fs::exists(first) && !first.has_extension();
}

std::string number(float v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Every vertex within 1e-5 of the mesh's diagonal from the plane of its largest triangle.
bool is_flat(const Mesh& m) {
  float best = -1;
  Vec3 n{0, 0, 0}, origin{0, 0, 0};
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], c = m.positions[m.indices[3 * t + 2]];
    const Vec3 cr = cross(b - a, c - a);
    const float area2 = length(cr);
    if (area2 > best) best = area2, n = cr / area2, origin = a;
  }
  if (!(best > 0)) return true;
  const float tolerance = 1e-5f * m.bounds().diagonal();
  for (const Vec3& p : m.positions)
    if (std::abs(dot(p - origin, n)) > tolerance) return false;
  return true;
}

// The objects of interest: the scene's objects whose meshes are not flat, or every object when all
// are flat (flatness survives an affine map, so an instance shares its mesh's).
std::vector<SceneObject> interest_objects(const Scene& scene) {
  std::vector<char> flat(scene.meshes.size());
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) flat[m] = is_flat(scene.meshes[m]);
  std::vector<SceneObject> all = scene.objects(), chosen;
  for (const SceneObject& o : all)
    if (!flat[o.mesh]) chosen.push_back(o);
  return chosen.empty() ? all : chosen;
}

// Auto-framing: from the front, a little to the right and above, the usual product shot, with the
// objects of interest fitted to the image.
constexpr Vec3 kFramingDirection{0.55f, 0.5f, 1.0f};
constexpr float kDefaultFov = 40.0f;
// The objects fill this fraction of the image along the axis that limits them: a margin of 2.5% on
// each side, so no silhouette touches the edge.
constexpr double kFill = 0.95;

// What auto-framing fits to the image, in world space: the vertices of the meshes of interest, and
// for each instance of a mesh the eight corners of its placed bounding box (20,000 instances of a
// large mesh would be billions of vertices; the box keeps the fit conservative). So a model on a
// ground plane fills the frame and the plane runs out of it. Visited, not copied: a scan's millions
// of vertices cost no memory here.
class FramingPoints {
 public:
  explicit FramingPoints(const Scene& scene) : scene_(scene), objects_(interest_objects(scene)), mesh_bounds_(scene.meshes.size()) {
    for (const SceneObject& o : objects_)
      if (o.instance != SceneObject::kNoInstance && mesh_bounds_[o.mesh].empty()) mesh_bounds_[o.mesh] = scene.meshes[o.mesh].bounds();
  }

  template <class Fn>
  void for_each(Fn&& fn) const {
    for (const SceneObject& o : objects_) {
      const Mesh& m = scene_.meshes[o.mesh];
      if (o.instance == SceneObject::kNoInstance) {
        for (const Vec3& p : m.positions) fn(p);
        continue;
      }
      const Affine3& to_world = scene_.instances[o.instance].object_to_world;
      const Bounds3& b = mesh_bounds_[o.mesh];
      for (int i = 0; i < 8; ++i) fn(to_world.point({i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z}));
    }
  }

 private:
  const Scene& scene_;
  std::vector<SceneObject> objects_;
  std::vector<Bounds3> mesh_bounds_;  // of the instanced meshes, computed once
};

struct Framing {
  Camera camera;
  double area = 0;  // the fraction of the image the points' projected bounding rectangle covers
};

// The eye's offset e along one image axis (x: `axis` 0, y: 1) that centres the points on it: with
// their coordinates a along the axis and depths d from the eye (camera basis, origin at `centre`,
// eye at depth ez), each projects to (a - e) / d, and the lowest and highest of those, each
// decreasing in e, are opposite for one e, found by bisection in [-reach, reach] (where the sum of
// the two changes sign). 30 halvings take the interval below float precision.
double centring_offset(const FramingPoints& points, const Frame& basis, Vec3 centre, double ez, int axis, double reach) {
  auto sum_of_extremes = [&](double e) {
    double low = kInfinity, high = -kInfinity;
    points.for_each([&](Vec3 p) {
      const Vec3 q = basis.to_local(p - centre);
      const double v = ((axis == 0 ? q.x : q.y) - e) / (ez - q.z);
      low = std::min(low, v), high = std::max(high, v);
    });
    return low + high;
  };
  double lo = -reach, hi = reach;
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    (sum_of_extremes(mid) > 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// A viewer's "frame all" along -`direction`: the eye where the points span kFill of the image along
// the axis that limits them (vertical or horizontal), centred on that axis and, with `centre`, on
// the other (else with equal room on both sides in depth units, which perspective makes a little
// uneven); every point inside the image. frame_bounds gives the orientation (and the answer when
// the points have no extent).
Framing fit_points(const FramingPoints& points, const Bounds3& bounds, Vec3 direction, float fov, int width, int height, bool centre) {
  Framing f{frame_bounds(bounds, direction, fov, width, height)};
  if (!(bounds.diagonal() > 0.0f)) return f;
  // In the camera basis (x right, y up, z towards the camera) with the origin at the box centre, a
  // point q is inside the image seen from the eye e when |q.x - e.x| <= tan_h (e.z - q.z) and
  // |q.y - e.y| <= tan_v (e.z - q.z). Each edge of the image is one family of parallel planes:
  //   right:  q.x + tan_h q.z <= tan_h e.z + e.x      left:   tan_h q.z - q.x <= tan_h e.z - e.x
  // and the same in y. The nearest eye makes both of an axis's inequalities equalities for its
  // extreme points: tan_h e.z = (right + left) / 2 and e.x = (right - left) / 2; the larger of the
  // two axes' e.z fits both.
  const Frame basis = f.camera.basis();
  const Vec3 box_centre = bounds.center();
  const double tan_v = static_cast<double>(f.camera.tan_half_fov()) * kFill, tan_h = tan_v * f.camera.aspect();
  double right = -kInfinity, left = -kInfinity, top = -kInfinity, bottom = -kInfinity, nearest = -kInfinity;
  points.for_each([&](Vec3 p) {
    const Vec3 q = basis.to_local(p - box_centre);
    right = std::max(right, q.x + tan_h * q.z), left = std::max(left, tan_h * q.z - q.x);
    top = std::max(top, q.y + tan_v * q.z), bottom = std::max(bottom, tan_v * q.z - q.y);
    nearest = std::max(nearest, static_cast<double>(q.z));
  });
  // A point on the view axis may set the eye on itself (a segment seen end on): keep the eye 1% of
  // the diagonal in front of the nearest point, so every point has a positive depth.
  const double ez_x = (right + left) / (2.0 * tan_h), ez_y = (top + bottom) / (2.0 * tan_v);
  const double ez = std::max({ez_x, ez_y, nearest + 0.01 * bounds.diagonal()});
  double ex = (right - left) / 2.0, ey = (top - bottom) / 2.0;
  if (centre) {
    const double reach = 2.0 * (ez + bounds.diagonal());  // beyond every point, seen from ez
    (ez_x >= ez_y ? ey : ex) = centring_offset(points, basis, box_centre, ez, ez_x >= ez_y ? 1 : 0, reach);
  }
  const Vec3 offset{static_cast<float>(ex), static_cast<float>(ey), 0.0f};
  f.camera.target = box_centre + basis.to_world(offset);
  f.camera.eye = f.camera.target + basis.n * static_cast<float>(ez);
  double span_x = 0, span_y = 0;  // half the rectangle, in tangent units
  points.for_each([&](Vec3 p) {
    const Vec3 q = basis.to_local(p - box_centre);
    span_x = std::max(span_x, std::abs(q.x - ex) / (ez - q.z)), span_y = std::max(span_y, std::abs(q.y - ey) / (ez - q.z));
  });
  f.area = std::min(1.0, span_x * kFill / tan_h) * std::min(1.0, span_y * kFill / tan_v);
  return f;
}

// Auto-framing: the product shot from the front right and above, unless a view from further round
// at the same height (front, front left, left, right) fills the image by a quarter more, as a tall
// model in a wide image does when turned sideways. Never from behind: the front of a model is where
// its author looked from.
Camera auto_frame(const Scene& scene, float fov, int width, int height) {
  const FramingPoints points(scene);
  Bounds3 bounds;
  points.for_each([&](Vec3 p) { bounds.extend(p); });
  Vec3 direction = kFramingDirection;
  const double needed = 1.25 * fit_points(points, bounds, direction, fov, width, height, false).area;
  const float side = std::hypot(kFramingDirection.x, kFramingDirection.z);  // the same height above the horizon
  double best = needed;
  for (const Vec3 d : {Vec3{0, kFramingDirection.y, side}, Vec3{-kFramingDirection.x, kFramingDirection.y, kFramingDirection.z},
                       Vec3{-side, kFramingDirection.y, 0}, Vec3{side, kFramingDirection.y, 0}}) {
    const double area = fit_points(points, bounds, d, fov, width, height, false).area;
    if (area > best) best = area, direction = d;
  }
  return fit_points(points, bounds, direction, fov, width, height, true).camera;
}

}  // namespace

std::string SceneSource::name() const {
  if (scene) return scene->name;
  if (args.empty()) return "default";
  if (names_builtin_scene(args)) return args[0];
  std::string joined;
  for (const std::string& a : args) {
    if (!joined.empty()) joined += '+';
    joined += fs::path(a).filename().string();
  }
  return joined;
}

std::vector<std::string> SceneSource::files() const {
  if (scene || args.empty() || names_builtin_scene(args)) return {};
  return args;
}

void SceneSource::declare_inputs(OutputSet& outputs) const {
  if (scene || args.empty() || names_builtin_scene(args)) return;
  for (const std::string& a : args) outputs.add_input(a, "the scene " + a);
}

std::shared_ptr<const Scene> SceneSource::load(const LoadOptions& options) const {
  if (scene) return scene;
  if (args.empty()) return std::make_shared<const Scene>(make_builtin_scene("default"));
  if (names_builtin_scene(args)) return std::make_shared<const Scene>(make_builtin_scene(args[0]));
  auto merged = std::make_shared<Scene>();
  for (const std::string& a : args) {
    Scene s = load_scene_file(a, options);
    merged->name += (merged->name.empty() ? "" : "+") + s.name;
    const auto first_mesh = static_cast<std::uint32_t>(merged->meshes.size());
    for (Instance& in : s.instances) {
      in.mesh += first_mesh;
      merged->instances.push_back(std::move(in));
    }
    for (Mesh& m : s.meshes) merged->meshes.push_back(std::move(m));
    for (std::string& w : s.warnings) merged->warnings.push_back(std::move(w));
  }
  return merged;
}

float interest_diagonal(const Scene& scene) {
  Bounds3 objects;
  for (const SceneObject& o : interest_objects(scene)) {
    const Mesh& m = scene.meshes[o.mesh];
    objects.extend(o.instance == SceneObject::kNoInstance ? m.bounds() : transform_bounds(scene.instances[o.instance].object_to_world, m.bounds()));
  }
  return objects.empty() ? scene.bounds().diagonal() : objects.diagonal();
}

PreparedScene::PreparedScene(std::shared_ptr<const Scene> s, const std::string& what, const BvhOptions& options) : scene(std::move(s)) {
  check_memory(estimate_ray_scene_memory(scene->stored_triangle_count(), scene->vertex_count(), scene->instances.size()),
               what + ": the BVH of " + std::to_string(scene->stored_triangle_count()) + " triangles");
  rays = std::make_unique<RayScene>(*scene, options);
  radius_basis = interest_diagonal(*scene);
}
PreparedScene::PreparedScene(std::shared_ptr<const Scene> s) : PreparedScene(std::move(s), "the scene", BvhOptions{}) {}
PreparedScene::PreparedScene(PreparedScene&&) noexcept = default;
PreparedScene& PreparedScene::operator=(PreparedScene&&) noexcept = default;
PreparedScene::~PreparedScene() = default;

void CameraRequest::validate() const {
  const auto side = [](const std::optional<int>& v, std::string_view name) {
    if (v && (*v < 1 || *v > kMaxImageSide))
      throw InputError(field(name) + " must be in [1, " + std::to_string(kMaxImageSide) + "] pixels, got " + std::to_string(*v));
  };
  side(width, fields::kCameraWidth);
  side(height, fields::kCameraHeight);
  if (fov && !(*fov > 0.0f && *fov < 180.0f)) throw InputError(field(fields::kCameraFov) + " must be in (0, 180) degrees, got " + number(*fov));
  const std::pair<const std::optional<Vec3>*, std::string_view> points[] = {
      {&eye, fields::kCameraEye}, {&target, fields::kCameraTarget}, {&up, fields::kCameraUp}};
  for (const auto& [p, name] : points)
    if (*p && !is_finite(**p)) throw InputError(field(name) + ": expected three finite numbers as x,y,z");
}

Camera choose_camera(const Scene& scene, const CameraRequest& request) {
  request.validate();
  const int width = request.width.value_or(request.default_width), height = request.height.value_or(request.default_height);
  Camera cam;
  if (request.file) {
    Camera defaults;
    defaults.width = width;
    defaults.height = height;
    cam = read_camera_file(*request.file, defaults);
    if (request.width) cam.width = *request.width;
    if (request.height) cam.height = *request.height;
  } else {
    cam = scene.preferred_view ? *scene.preferred_view : auto_frame(scene, request.fov.value_or(kDefaultFov), width, height);
    cam.width = width;
    cam.height = height;
  }
  if (request.fov) cam.vertical_fov_deg = *request.fov;
  if (request.up) cam.up = *request.up;
  if (request.target) cam.target = *request.target;
  if (request.eye) {
    cam.eye = *request.eye;
  } else if (request.target && !scene.preferred_view && !request.file) {
    // Keep the framing distance and direction, looking at the new target.
    const Camera framed = auto_frame(scene, cam.vertical_fov_deg, cam.width, cam.height);
    cam.eye = cam.target + (framed.eye - framed.target);
  }
  cam.validate();
  return cam;
}

void FalloffRequest::validate() const {
  if (radius && !(*radius > 0.0f && std::isfinite(*radius)))
    throw InputError(field(fields::kFalloffRadius) + " must be a positive finite number of world units, got " + std::to_string(*radius));
  if (!radius && !(radius_fraction > 0.0f && radius_fraction <= 10.0f))
    throw InputError(field(fields::kFalloffRadiusFraction) + " must be in (0, 10], got " + std::to_string(radius_fraction));
  if (!(tau >= 0.0f && std::isfinite(tau))) throw InputError(field(fields::kFalloffTau) + " must be >= 0 (0 selects 3/R), got " + std::to_string(tau));
}

Falloff choose_falloff(const FalloffRequest& request, float diagonal) {
  request.validate();
  Falloff f{request.membership, request.radius ? *request.radius : request.radius_fraction * diagonal, request.tau};
  f.validate();
  return f;
}

Membership membership_from_name(const std::string& name) {
  const auto m = parse_membership(name);
  if (!m) throw InputError(field(fields::kFalloffMembership) + ": unknown '" + name + "' (known: " + membership_names() + ")" + did_you_mean(name, membership_names()));
  return *m;
}

SurfaceNormal surface_normal_from_name(const std::string& name) {
  if (name == "shading") return SurfaceNormal::Shading;
  if (name == "geometric") return SurfaceNormal::Geometric;
  throw InputError(field(fields::kNormal) + ": expected shading or geometric, got '" + name + "'" + did_you_mean(name, "shading, geometric"));
}

const char* to_string(SurfaceNormal normal) { return normal == SurfaceNormal::Geometric ? "geometric" : "shading"; }

}  // namespace ao
