// scene_place.cpp — a scene's objects placed in one frame: their meshes loaded, transformed to
// world space and offset from the scene's origin (bake/bake/scene.h, bake/mesh/mesh.h ORIGIN).
#include <bake/bake/scene.h>
#include <bake/core/error.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace prt::bake {

std::vector<Mesh> load_scene_meshes(const SceneDescription& scene, std::vector<std::string>& warnings) {
  // The files' meshes first (a glTF's instances are already in world space: their objects'
  // transforms are the identity), then one scene origin over all of them, so that receivers and
  // occluders share one frame (bake/mesh/mesh.h ORIGIN), then each object placed in it.
  std::vector<Mesh> files;
  if (is_gltf_scene(scene.file)) {
    MeshInstances file = load_mesh_instances(scene.file);
    if (file.instances.size() != scene.objects.size())
      throw InputError(scene.file.string(), "has changed since it was read: " + std::to_string(file.instances.size()) +
                                                " instances, was " + std::to_string(scene.objects.size()));
    warnings.insert(warnings.end(), file.warnings.begin(), file.warnings.end());
    for (MeshInstance& in : file.instances) files.push_back(std::move(in.mesh));
  } else {
    for (const SceneObject& o : scene.objects) {
      try {
        files.push_back(load_mesh(o.mesh));
      } catch (const InputError& e) {  // say which object of which scene wanted the mesh
        throw InputError(e.file(), e.defect() + " (object '" + o.name + "' of " + scene.file.string() + ")");
      }
      warnings.insert(warnings.end(), files.back().warnings.begin(), files.back().warnings.end());
    }
  }
  const Eigen::Vector3d origin = scene_origin(files, scene.objects);
  std::vector<Mesh> meshes;
  meshes.reserve(files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    try {
      meshes.push_back(place_scene_object(files[i], scene.objects[i], origin));
    } catch (const InputError& e) {
      throw InputError(e.file(), e.defect() + " (object '" + scene.objects[i].name + "' of " + scene.file.string() + ")");
    }
  }
  return meshes;
}

namespace {

// world_from_object applied in double to the file mesh's world positions (unchecked).
std::vector<Eigen::Vector3d> world_positions(const Mesh& file_mesh, const SceneObject& object) {
  const Eigen::Matrix3d A = object.world_from_object.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = object.world_from_object.topRightCorner<3, 1>();
  std::vector<Eigen::Vector3d> world(file_mesh.positions.size());
  for (size_t i = 0; i < world.size(); ++i) world[i] = A * file_mesh.world_position(i) + t;
  return world;
}

bool usable(const Eigen::Vector3d& p) { return p.allFinite() && p.cwiseAbs().maxCoeff() <= 1e30; }

} // namespace

Eigen::Vector3d scene_origin(std::span<const Mesh> file_meshes, std::span<const SceneObject> objects) {
  PRT_CHECK_OP(file_meshes.size(), ==, objects.size());
  Eigen::AlignedBox3d bounds;
  for (size_t i = 0; i < objects.size(); ++i)
    for (const Eigen::Vector3d& p : world_positions(file_meshes[i], objects[i]))
      if (usable(p)) bounds.extend(p);  // the others are refused by place_scene_object
  return bounds.isEmpty() ? Eigen::Vector3d::Zero() : frame_origin(bounds);
}

Mesh load_scene_mesh(const SceneObject& object) {
  const Mesh file_mesh = load_mesh(object.mesh);
  return place_scene_object(file_mesh, object, scene_origin(std::span(&file_mesh, 1), std::span(&object, 1)));
}

Mesh place_scene_object(const Mesh& file_mesh, const SceneObject& object, const Eigen::Vector3d& origin) {
  Mesh m = file_mesh;
  const Eigen::Matrix3d N = object.world_from_object.topLeftCorner<3, 3>().inverse().transpose();
  const std::vector<Eigen::Vector3d> world = world_positions(file_mesh, object);
  for (size_t i = 0; i < world.size(); ++i)
    if (!usable(world[i]))
      throw InputError(object.mesh.string(), "vertex " + std::to_string(i) + " is not finite after the scene transform of '" +
                                                 object.name + "'");
  m.positions = offsets_from(world, origin, object.mesh.string());
  m.origin = origin;
  if (m.normal_source == Mesh::NormalSource::File) {
    for (auto& n : m.normals) n = (N * n.cast<double>()).normalized().cast<float>();
  } else {
    m.normals = welded_angle_weighted_normals(m.positions, m.triangles);
  }
  return m;
}

std::vector<std::string> SceneDescription::light_names() const {
  std::vector<std::string> names;
  for (const AreaLight& l : lights) names.push_back(l.name);
  for (const PunctualLight& l : punctual_lights) names.push_back(l.name);
  return names;
}

void place_suns(SceneDescription& scene, std::span<const Mesh> meshes) {
  // The ball about the world-space bounds of every mesh (the origin added back in double).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Mesh& m : meshes)
    for (const Eigen::Vector3f& p : m.positions) {
      const Eigen::Vector3d w = m.origin + p.cast<double>();
      lo = lo.cwiseMin(w), hi = hi.cwiseMax(w);
    }
  const bool empty = !(lo.x() <= hi.x());
  const Eigen::Vector3d centre = empty ? Eigen::Vector3d::Zero() : Eigen::Vector3d((lo + hi) / 2);
  // At least 1 unit: a scene of one flat point still gets a sun beyond it.
  const double radius = std::max(1.0, empty ? 0.0 : (hi - lo).norm() / 2);
  std::vector<PunctualLight> rest;
  for (PunctualLight& l : scene.punctual_lights) {
    if (l.kind == PunctualKind::Directional && l.angular_diameter > 0) {
      AreaLight sun = sun_light(l, centre, radius);
      validate_light(sun, scene.file.string(), "the sun \"" + l.name + "\"");
      scene.lights.push_back(std::move(sun));
    } else {
      rest.push_back(std::move(l));
    }
  }
  scene.punctual_lights = std::move(rest);
}

} // namespace prt::bake
