#include <bench_common.h>

#include <bake/bake/vertex_bake.h>
#include <bake/mesh/subdivide.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace prt::bench {
namespace {

constexpr uint32_t kBunnyVertices = 1839, kBunnyTriangles = 3674;  // data/README.md

// The first kBunnyVertices / kBunnyTriangles of bunny_ground.obj are the bunny, the rest the
// ground grid (data/make_default_scene.py).
void split(const bake::Mesh& file, bake::Mesh& bunny, bake::Mesh& ground) {
  if (file.positions.size() <= kBunnyVertices || file.triangles.size() <= kBunnyTriangles)
    throw std::runtime_error(file.source + ": not the bunny + ground scene");
  std::vector<Eigen::Vector3f> bp(file.positions.begin(), file.positions.begin() + kBunnyVertices);
  std::vector<Eigen::Vector3f> gp(file.positions.begin() + kBunnyVertices, file.positions.end());
  std::vector<std::array<uint32_t, 3>> bt, gt;
  for (size_t t = 0; t < file.triangles.size(); ++t) {
    auto tri = file.triangles[t];
    if (t < kBunnyTriangles) {
      for (uint32_t v : tri)
        if (v >= kBunnyVertices) throw std::runtime_error(file.source + ": bunny triangle uses a ground vertex");
      bt.push_back(tri);
    } else {
      for (uint32_t& v : tri) {
        if (v < kBunnyVertices) throw std::runtime_error(file.source + ": ground triangle uses a bunny vertex");
        v -= kBunnyVertices;
      }
      gt.push_back(tri);
    }
  }
  bunny = bake::make_mesh(std::move(bp), std::move(bt), "bunny");
  ground = bake::make_mesh(std::move(gp), std::move(gt), "ground");
}

} // namespace

bake::ProductRequest request() {
  bake::ProductRequest r;
  r.ao = true;
  r.transfer_order = 3;
  return r;
}

long env_long(const char* name, long fallback) {
  const char* s = std::getenv(name);
  if (!s || !*s) return fallback;
  char* end = nullptr;
  const long v = std::strtol(s, &end, 10);
  if (*end) throw std::runtime_error(std::string(name) + "=" + s + ": not an integer");
  return v;
}

std::vector<long> env_list(const char* name, std::vector<long> fallback) {
  const char* s = std::getenv(name);
  if (!s || !*s) return fallback;
  std::vector<long> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const long v = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end) throw std::runtime_error(std::string(name) + "=" + s + ": not a list of integers");
    out.push_back(v);
  }
  return out;
}

size_t n_points() { return size_t(env_long("PRT_BENCH_POINTS", 64)); }
uint64_t sample_seed() { return uint64_t(env_long("PRT_BENCH_SEED", 7)); }

const Scene& scene(int level) {
  static std::mutex m;
  static std::map<int, std::unique_ptr<Scene>> cache;
  std::lock_guard<std::mutex> lock(m);
  auto& slot = cache[level];
  if (slot) return *slot;
  const auto t0 = std::chrono::steady_clock::now();
  auto s = std::make_unique<Scene>();
  s->level = level;
  const bake::Mesh file = bake::load_mesh(std::string(PRT_DATA_DIR) + "/bunny_ground.obj");
  const std::vector<uint32_t> base = bake::seeded_sample(uint32_t(file.positions.size()), n_points(), sample_seed());
  if (level == 0) {
    s->mesh = file;
    s->bunny_vertices = kBunnyVertices;
    s->vertices = base;
  } else {
    bake::Mesh bunny, ground;
    split(file, bunny, ground);
    const bake::Mesh fine = bake::loop_subdivide(bunny, level);
    const bake::Mesh parts[] = {fine, ground};
    s->mesh = bake::merge_meshes(parts, "bunny_ground.obj, bunny loop x" + std::to_string(level));
    s->bunny_vertices = uint32_t(fine.positions.size());
    const uint32_t shift = s->bunny_vertices - kBunnyVertices;
    for (uint32_t v : base) s->vertices.push_back(v < kBunnyVertices ? v : v + shift);
  }
  s->topology = bake::build_topology(s->mesh);
  for (uint32_t v : s->vertices) s->points.push_back(bake::vertex_shade_point(s->mesh, s->topology, v));
  s->build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  slot = std::move(s);
  return *slot;
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

} // namespace prt::bench
