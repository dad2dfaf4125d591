#include "ao/jobs/inputs.h"

#include <cmath>
#include <sstream>

#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/io/camera_json.h"
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

// Auto-framing: from the front, a little to the right and above, the usual product shot.
constexpr Vec3 kFramingDirection{0.55f, 0.5f, 1.0f};
constexpr float kDefaultFov = 40.0f;

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
  for (const SceneObject& o : scene.objects()) {
    const Mesh& m = scene.meshes[o.mesh];
    if (is_flat(m)) continue;  // flatness survives an affine map
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
  const auto side = [](const std::optional<int>& v, const char* option) {
    if (v && (*v < 1 || *v > kMaxImageSide))
      throw InputError(std::string(option) + " must be in [1, " + std::to_string(kMaxImageSide) + "] pixels, got " + std::to_string(*v));
  };
  side(width, "--width");
  side(height, "--height");
  if (fov && !(*fov > 0.0f && *fov < 180.0f)) throw InputError("--fov must be in (0, 180) degrees, got " + number(*fov));
  const std::pair<const std::optional<Vec3>*, const char*> points[] = {{&eye, "--eye"}, {&target, "--target"}, {&up, "--up"}};
  for (const auto& [p, option] : points)
    if (*p && !is_finite(**p)) throw InputError(std::string(option) + ": expected three finite numbers as x,y,z");
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
    cam = scene.preferred_view ? *scene.preferred_view : frame_bounds(scene.bounds(), kFramingDirection, request.fov.value_or(kDefaultFov), width, height);
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
    const Camera framed = frame_bounds(scene.bounds(), kFramingDirection, cam.vertical_fov_deg, cam.width, cam.height);
    cam.eye = cam.target + (framed.eye - framed.target);
  }
  cam.validate();
  return cam;
}

void FalloffRequest::validate() const {
  if (radius && !(*radius > 0.0f && std::isfinite(*radius)))
    throw InputError("--radius must be a positive finite number of world units, got " + std::to_string(*radius));
  if (!radius && !(radius_fraction > 0.0f && radius_fraction <= 10.0f))
    throw InputError("--radius-fraction must be in (0, 10], got " + std::to_string(radius_fraction));
  if (!(tau >= 0.0f && std::isfinite(tau))) throw InputError("--tau must be >= 0 (0 selects 3/R), got " + std::to_string(tau));
}

Falloff choose_falloff(const FalloffRequest& request, float diagonal) {
  request.validate();
  Falloff f{request.membership, request.radius ? *request.radius : request.radius_fraction * diagonal, request.tau};
  f.validate();
  return f;
}

Membership membership_from_name(const std::string& name) {
  const auto m = parse_membership(name);
  if (!m) throw InputError("--membership: unknown '" + name + "' (known: " + membership_names() + ")");
  return *m;
}

SurfaceNormal surface_normal_from_name(const std::string& name) {
  if (name == "shading") return SurfaceNormal::Shading;
  if (name == "geometric") return SurfaceNormal::Geometric;
  throw InputError("--normal: expected shading or geometric, got '" + name + "'");
}

const char* to_string(SurfaceNormal normal) { return normal == SurfaceNormal::Geometric ? "geometric" : "shading"; }

}  // namespace ao
