// asset.cpp — the typed asset model <-> the generic File (see formats/asset.h). Each struct's
// typed attributes are one field table (name, member); the tables' order is the order in which
// attributes are written, so a file's bytes do not depend on how the asset was built.
#include <formats/asset.h>
#include <formats/names.h>

#include <algorithm>
#include <span>

namespace prt::formats {
namespace {

namespace N = names;

// ---- field tables ----------------------------------------------------------------------

template <class S>
using Member = std::variant<std::optional<std::string> S::*, std::optional<int64_t> S::*,
                            std::optional<double> S::*, std::optional<std::vector<double>> S::*,
                            std::string S::*, double S::*, std::vector<double> S::*,
                            std::array<double, 3> S::*>;

template <class S> struct Field {
  std::string_view name;
  Member<S> member;
};

template <class T> void emit(std::vector<Attr>& out, std::string_view name, const std::optional<T>& v) {
  if (v) out.push_back({std::string(name), *v});
}
template <class T> void emit(std::vector<Attr>& out, std::string_view name, const T& v) {
  out.push_back({std::string(name), v});
}
void emit(std::vector<Attr>& out, std::string_view name, const std::array<double, 3>& v) {
  out.push_back({std::string(name), std::vector<double>(v.begin(), v.end())});
}

// Sets `dst` from `v` when the types agree; false leaves the attribute to the extras.
template <class T> bool assign(std::optional<T>& dst, const AttrValue& v) {
  const auto* x = std::get_if<T>(&v);
  if (x) dst = *x;
  return x != nullptr;
}
template <class T> bool assign(T& dst, const AttrValue& v) {
  const auto* x = std::get_if<T>(&v);
  if (x) dst = *x;
  return x != nullptr;
}
bool assign(std::array<double, 3>& dst, const AttrValue& v) {
  const auto* x = std::get_if<std::vector<double>>(&v);
  if (x == nullptr || x->size() != 3) return false;
  std::copy(x->begin(), x->end(), dst.begin());
  return true;
}

// The typed attributes of `s` in table order, then its extras.
template <class S>
std::vector<Attr> attrs_of(const S& s, std::span<const Field<S>> table, const ExtraAttrs& extra) {
  std::vector<Attr> out;
  for (const Field<S>& f : table) std::visit([&](auto m) { emit(out, f.name, s.*m); }, f.member);
  out.insert(out.end(), extra.begin(), extra.end());
  return out;
}

// Fills the typed fields of `s` from `attrs`; what the table does not take goes to `extra`.
template <class S>
void take_attrs(S& s, std::span<const Field<S>> table, const std::vector<Attr>& attrs, ExtraAttrs& extra) {
  for (const Attr& a : attrs) {
    bool used = false;
    for (const Field<S>& f : table)
      if (f.name == a.name) std::visit([&](auto m) { used = assign(s.*m, a.value); }, f.member);
    if (!used) extra.push_back(a);
  }
}

constexpr Field<RootInfo> kRootFields[] = {
    {N::kGenerator, &RootInfo::generator},         {N::kCreated, &RootInfo::created},
    {N::kCommandLine, &RootInfo::command_line},    {N::kSource, &RootInfo::source},
    {N::kSourceSha256, &RootInfo::source_sha256},  {N::kUpAxis, &RootInfo::up_axis},
    {N::kShConvention, &RootInfo::sh_convention}};

constexpr Field<Normals> kNormalsFields[] = {{N::kSource, &Normals::source}};

constexpr Field<Product> kProductFields[] = {
    {N::kIntegrand, &Product::integrand},
    {N::kShOrder, &Product::sh_order},
    {N::kShading, &Product::shading},
    {N::kEnvironment, &Product::environment},
    {N::kEnvironmentSha256, &Product::environment_sha256},
    {N::kEnvironmentLayout, &Product::environment_layout},
    {N::kNegativePixelsClamped, &Product::negative_pixels_clamped},
    {N::kIntegrator, &Product::integrator},
    {N::kIntegratorDescription, &Product::integrator_description},
    {N::kSamples, &Product::samples},
    {N::kSeed, &Product::seed},
    {N::kVisibility, &Product::visibility},
    {N::kLightOrder, &Product::lights},
    {N::kBounces, &Product::bounces},
    {N::kBouncesRequested, &Product::bounces_requested},
    {N::kAlbedo, &Product::albedo},
    {N::kBounceRays, &Product::bounce_rays},
    {N::kBounceStdError, &Product::bounce_std_error}};

constexpr Field<ReportRow> kReportFields[] = {
    {N::kColumns, &ReportRow::columns},
    {N::kPoints, &ReportRow::points},
    {N::kReference, &ReportRow::reference},
    {N::kReferenceSeconds, &ReportRow::reference_seconds},
    {N::kBakeSeconds, &ReportRow::bake_seconds},
    {N::kIntegralsPerSecond, &ReportRow::integrals_per_second},
    {N::kMeshRms, &ReportRow::mesh_rms}};

constexpr Field<Uvs> kUvFields[] = {{N::kUvSet, &Uvs::uv_set}};

constexpr Field<Lightmap> kStateFields[] = {{N::kPadding, &Lightmap::padding}};  // of /lightmap/state

constexpr Field<FivEnvironment> kFivEnvironmentFields[] = {
    {N::kEnvironment, &FivEnvironment::environment},
    {N::kEnvironmentSha256, &FivEnvironment::environment_sha256},
    {N::kIntegrand, &FivEnvironment::integrand}};

constexpr Field<IrradianceCube> kCubeFields[] = {
    {N::kEnvironment, &IrradianceCube::environment},
    {N::kEnvironmentSha256, &IrradianceCube::environment_sha256},
    {N::kIntegrand, &IrradianceCube::integrand},
    {N::kFaceConvention, &IrradianceCube::face_convention}};

constexpr Field<Occluder> kShellsFields[] = {
    {N::kEnvironment, &Occluder::environment},
    {N::kEnvironmentSha256, &Occluder::environment_sha256},
    {N::kIntegrand, &Occluder::integrand},
    {N::kCentre, &Occluder::centre},
    {N::kRadius, &Occluder::radius},
    {N::kRadii, &Occluder::radii},
    {N::kAngularConvention, &Occluder::angular_convention},
    {N::kFraction, &Occluder::fraction},
    {N::kSamples, &Occluder::samples},
    {N::kGrid, &Occluder::grid},
    {N::kRadialScheme, &Occluder::radial_scheme},
    {N::kFirstOffset, &Occluder::first_offset}};

constexpr Field<Light> kLightFields[] = {
    {N::kShape, &Light::shape},
    {N::kRadiance, &Light::radiance},
    {N::kTwoSided, &Light::two_sided},
    {N::kPosition, &Light::position},
    {N::kDirection, &Light::direction},
    {N::kInnerConeAngle, &Light::inner_cone_angle},
    {N::kOuterConeAngle, &Light::outer_cone_angle},
    {N::kRange, &Light::range}};

constexpr Field<OccluderValid> kValidFields[] = {{N::kMeaning, &OccluderValid::meaning}};
constexpr Field<OccluderSurfaceRadius> kSurfaceRadiusFields[] = {{N::kMeaning, &OccluderSurfaceRadius::meaning}};
constexpr Field<OccluderCones> kConesFields[] = {{N::kIntegrand, &OccluderCones::integrand}};
constexpr Field<OccluderSelfBand1> kSelfBand1Fields[] = {{N::kMeaning, &OccluderSelfBand1::meaning}};

constexpr Field<SceneInfo> kSceneFields[] = {
    {N::kSceneFile, &SceneInfo::scene_file},
    {N::kIntegrator, &SceneInfo::integrator},
    {N::kSamples, &SceneInfo::samples},
    {N::kSeed, &SceneInfo::seed},
    {N::kShTolerance, &SceneInfo::sh_tolerance},
    {N::kRelight, &SceneInfo::relight},
    {N::kEnvironment, &SceneInfo::environment},
    {N::kEnvironmentSha256, &SceneInfo::environment_sha256},
    {N::kPlan, &SceneInfo::plan},
    {N::kOptionsFile, &SceneInfo::options_file},
    {N::kOptionsSha256, &SceneInfo::options_sha256}};

constexpr Field<SceneObject> kObjectFields[] = {
    {N::kRole, &SceneObject::role},
    {N::kMesh, &SceneObject::mesh},
    {N::kMeshSha256, &SceneObject::mesh_sha256},
    {N::kTransform, &SceneObject::transform},
    {N::kAlbedo, &SceneObject::albedo},
    {N::kPhongExponent, &SceneObject::phong_exponent},
    {N::kShOrderDiffuse, &SceneObject::sh_order_diffuse},
    {N::kShOrderGlossy, &SceneObject::sh_order_glossy},
    {N::kBaked, &SceneObject::baked},
    {N::kLeftOut, &SceneObject::left_out},
    {N::kSpecular, &SceneObject::specular},
    {N::kClosedFormVertices, &SceneObject::closed_form_vertices},
    {N::kNodePath, &SceneObject::node_path}};

// ---- paths -------------------------------------------------------------------------------

std::string cat(std::string_view a, std::string_view b) { return std::string(a) + std::string(b); }
std::string object_prefix(std::string_view name) { return cat(N::kObjects, "/") + std::string(name); }
std::string object_report_dir(std::string_view name) { return cat(N::kReport, object_prefix(name)); }
std::string occluder_dir(std::string_view name) { return cat(N::kOccluders, "/") + std::string(name); }
std::string fiv_report_path(std::string_view name) { return cat(N::kReportFiv, "/") + std::string(name); }
std::string light_dir(std::string_view name) { return cat(N::kLights, "/") + std::string(name); }

// ---- Asset -> File -----------------------------------------------------------------------

void add_array(File& f, const std::string& path, std::vector<uint64_t> shape, DatasetData data,
               std::vector<Attr> attrs) {
  f.datasets.push_back({path, std::move(shape), std::move(data), std::move(attrs)});
}

// ---- products: per vertex and per texel ---------------------------------------------------
// A product runs along [V] (per vertex) or [H, W] (per texel of a lightmap), then along axes of
// its own, the same in both (SCHEMA.md).

// The L*L width of an SH product (L = sh_order; else what its values give for `rows` rows).
uint64_t sh_width(const Product& p, uint64_t rows) {
  if (p.sh_order) return uint64_t(*p.sh_order * *p.sh_order);
  return rows ? p.values.size() / rows : 0;
}
uint64_t light_count(const Product& p) { return p.lights ? uint64_t(split_light_list(*p.lights).size()) : 0; }

// A product's own axes, for `n` rows.
using OwnAxes = std::vector<uint64_t> (*)(const Product& p, uint64_t n);
std::vector<uint64_t> no_axes(const Product&, uint64_t) { return {}; }
std::vector<uint64_t> sh_axes(const Product& p, uint64_t n) { return {sh_width(p, n)}; }
std::vector<uint64_t> rgb_m_axes(const Product&, uint64_t) { return {3, 3}; }
std::vector<uint64_t> rgb_sh_axes(const Product& p, uint64_t n) { return {3, sh_width(p, 3 * n)}; }
std::vector<uint64_t> light_axes(const Product& p, uint64_t) { return {light_count(p)}; }
std::vector<uint64_t> light_sh_axes(const Product& p, uint64_t n) {
  const uint64_t L = light_count(p);
  return {L, sh_width(p, n * L)};
}

// Where a product of S lives: its path under the vertex set, its kind, its member, its own axes.
template <class S> struct ProductSlot {
  std::string_view path;
  DatasetKind kind;
  std::optional<Product> S::*member;
  OwnAxes own;
};

// In the order they are written.
constexpr ProductSlot<VertexSet> kVertexProducts[] = {
    {N::kAo, DatasetKind::ao, &VertexSet::ao, no_axes},
    {N::kTransferDiffuse, DatasetKind::transfer_diffuse, &VertexSet::transfer_diffuse, sh_axes},
    {N::kTransferVisibility, DatasetKind::transfer_visibility, &VertexSet::transfer_visibility, sh_axes},
    {N::kRadianceBand1, DatasetKind::radiance_band1, &VertexSet::radiance_band1, rgb_m_axes},
    {N::kRadianceShadowed, DatasetKind::radiance_shadowed, &VertexSet::radiance_shadowed, rgb_sh_axes},
    {N::kAreaIrradiance, DatasetKind::area_irradiance, &VertexSet::area_irradiance, light_axes},
    {N::kAreaSh, DatasetKind::area_sh, &VertexSet::area_sh, light_sh_axes}};

constexpr ProductSlot<Lightmap> kTexelProducts[] = {
    {N::kLightmapAo, DatasetKind::lightmap_ao, &Lightmap::ao, no_axes},
    {N::kLightmapTransferDiffuse, DatasetKind::lightmap_transfer_diffuse, &Lightmap::transfer_diffuse, sh_axes},
    {N::kLightmapTransferVisibility, DatasetKind::lightmap_transfer_visibility, &Lightmap::transfer_visibility, sh_axes},
    {N::kLightmapRadianceBand1, DatasetKind::lightmap_radiance_band1, &Lightmap::radiance_band1, rgb_m_axes},
    {N::kLightmapRadianceShadowed, DatasetKind::lightmap_radiance_shadowed, &Lightmap::radiance_shadowed, rgb_sh_axes},
    {N::kLightmapAreaIrradiance, DatasetKind::lightmap_area_irradiance, &Lightmap::area_irradiance, light_axes},
    {N::kLightmapAreaSh, DatasetKind::lightmap_area_sh, &Lightmap::area_sh, light_sh_axes}};

// Writes the products `s` holds under `prefix`, each along `rows` and then its own axes.
template <class S>
void add_products(File& f, const std::string& prefix, std::span<const ProductSlot<S>> slots, const S& s,
                  const std::vector<uint64_t>& rows) {
  const uint64_t n = shape_product(rows);
  for (const ProductSlot<S>& slot : slots) {
    const std::optional<Product>& p = s.*slot.member;
    if (!p) continue;
    std::vector<uint64_t> shape = rows;
    const std::vector<uint64_t> own = slot.own(*p, n);
    shape.insert(shape.end(), own.begin(), own.end());
    add_array(f, cat(prefix, slot.path), std::move(shape), p->values, attrs_of<Product>(*p, kProductFields, p->extra));
  }
}

std::vector<Attr> row_attrs(const ReportRow& r) { return attrs_of<ReportRow>(r, kReportFields, r.extra); }

void add_row(File& f, const std::string& path, const ReportRow& r) {
  add_array(f, path, {5}, std::vector<float>(r.values.begin(), r.values.end()), row_attrs(r));
}

void add_report(File& f, const std::string& dir, const Report& r) {
  for (const ReportRow& row : r.rows) add_row(f, dir + "/" + row.product, row);
  if (r.vertices)
    add_array(f, cat(dir + "/", N::kReportVertices), {r.vertices->values.size()}, r.vertices->values,
              r.vertices->extra);
}

// Positions on disk: float32 when every coordinate is a float32 exactly, else float64 (asset.h).
DatasetData positions_data(const std::vector<double>& values) {
  const bool all_float = std::all_of(values.begin(), values.end(),
                                     [](double x) { return static_cast<double>(static_cast<float>(x)) == x; });
  if (!all_float) return values;
  return std::vector<float>(values.begin(), values.end());
}

// A vertex set's lightmap (v5): the texels' state [H, W], which the others run along, their
// surface points, then the products as a vertex set's.
void add_lightmap(File& f, const std::string& prefix, const Lightmap& m) {
  const std::vector<uint64_t> texels = {m.height, m.width};
  add_array(f, cat(prefix, N::kLightmapState), texels, m.state.values, attrs_of<Lightmap>(m, kStateFields, m.state.extra));
  if (m.positions)
    add_array(f, cat(prefix, N::kLightmapPositions), {m.height, m.width, 3}, positions_data(m.positions->values),
              m.positions->extra);
  if (m.normals) add_array(f, cat(prefix, N::kLightmapNormals), {m.height, m.width, 3}, m.normals->values, m.normals->extra);
  add_products<Lightmap>(f, prefix, kTexelProducts, m, texels);
}

void add_vertex_set(File& f, const std::string& prefix, const std::string& report_dir, const VertexSet& s) {
  const uint64_t V = s.vertex_count();
  if (s.positions) add_array(f, cat(prefix, N::kPositions), {V, 3}, positions_data(s.positions->values), s.positions->extra);
  if (s.normals)
    add_array(f, cat(prefix, N::kNormals), {s.normals->values.size() / 3, 3}, s.normals->values,
              attrs_of<Normals>(*s.normals, kNormalsFields, s.normals->extra));
  if (s.triangles)
    add_array(f, cat(prefix, N::kTriangles), {s.triangles->values.size() / 3, 3}, s.triangles->values,
              s.triangles->extra);
  if (s.source_position)
    add_array(f, cat(prefix, N::kSourcePosition), {s.source_position->values.size()}, s.source_position->values,
              s.source_position->extra);
  add_products<VertexSet>(f, prefix, kVertexProducts, s, {V});
  if (s.uv)  // v5, after everything of version 4: a file without it keeps its bytes
    add_array(f, cat(prefix, N::kUv), {s.uv->values.size() / 6, 3, 2}, s.uv->values,
              attrs_of<Uvs>(*s.uv, kUvFields, s.uv->extra));
  if (s.lightmap) add_lightmap(f, prefix, *s.lightmap);
  add_report(f, report_dir, s.report);
}

// float32 values as they are, or rounded to float16 (v8).
DatasetData stored(const std::vector<float>& v, bool float16) {
  if (!float16) return v;
  std::vector<Float16> h(v.size());
  std::transform(v.begin(), v.end(), h.begin(), to_float16);
  return h;
}

void add_occluder(File& f, const Occluder& o) {
  const std::string dir = occluder_dir(o.name) + "/";
  const std::vector<uint64_t> grid = {uint64_t(o.n_rho), uint64_t(o.n_theta), uint64_t(o.n_phi)};
  add_array(f, cat(dir, N::kShells), {grid[0], grid[1], grid[2], 3, 3}, stored(o.shells, o.float16), shells_attrs(o));
  if (o.valid)
    add_array(f, cat(dir, N::kValid), grid, o.valid->values,
              attrs_of<OccluderValid>(*o.valid, kValidFields, o.valid->extra));
  if (o.surface_radius)
    add_array(f, cat(dir, N::kSurfaceRadius), {grid[1], grid[2]}, o.surface_radius->values,
              attrs_of<OccluderSurfaceRadius>(*o.surface_radius, kSurfaceRadiusFields, o.surface_radius->extra));
  if (o.cones)  // v7
    add_array(f, cat(dir, N::kCones), {grid[0], grid[1], grid[2], 4}, stored(o.cones->values, o.cones->float16),
              attrs_of<OccluderCones>(*o.cones, kConesFields, o.cones->extra));
  if (o.self_band1)  // v9
    add_array(f, cat(dir, N::kSelfBand1), {o.self_band1->values.size() / 9, 3, 3}, o.self_band1->values,
              attrs_of<OccluderSelfBand1>(*o.self_band1, kSelfBand1Fields, o.self_band1->extra));
  if (o.report) add_row(f, fiv_report_path(o.name), *o.report);
}

void add_light(File& f, const Light& l) {
  if (N::is_punctual_shape(l.shape)) return;  // v6: attributes only
  const std::string dir = light_dir(l.name) + "/";
  add_array(f, cat(dir, N::kLightVertices), {l.vertices.values.size() / 3, 3}, l.vertices.values, l.vertices.extra);
  add_array(f, cat(dir, N::kLightFaceSizes), {l.face_sizes.values.size()}, l.face_sizes.values, l.face_sizes.extra);
  add_array(f, cat(dir, N::kLightFaceIndices), {l.face_indices.values.size()}, l.face_indices.values,
            l.face_indices.extra);
}

// ---- File -> Asset -----------------------------------------------------------------------

template <class T> const std::vector<T>& values(const Dataset& d) { return std::get<std::vector<T>>(d.data); }

// The values of a float32 or float16 (v8) dataset as floats; `float16` says which it was.
std::vector<float> float_values(const Dataset& d, bool& float16) {
  float16 = d.data.index() == 4;
  if (!float16) return values<float>(d);
  const std::vector<Float16>& h = values<Float16>(d);
  std::vector<float> v(h.size());
  std::transform(h.begin(), h.end(), v.begin(), static_cast<float (*)(Float16)>(to_float));
  return v;
}

template <class T> Array<T> array_of(const Dataset& d) { return {values<T>(d), d.attrs}; }

Product product_of(const Dataset& d) {
  Product p;
  p.values = values<float>(d);
  take_attrs<Product>(p, kProductFields, d.attrs, p.extra);
  return p;
}

bool is_row(const Dataset& d) { return d.shape == std::vector<uint64_t>{5} && d.data.index() == 0; }

ReportRow row_of(const Dataset& d, std::string product) {
  ReportRow r;
  r.product = std::move(product);
  std::copy_n(values<float>(d).begin(), 5, r.values.begin());
  take_attrs<ReportRow>(r, kReportFields, d.attrs, r.extra);
  return r;
}

// Puts report dataset `d` (its path is `dir` + "/" + `leaf`) into `r` when it has a typed form.
bool take_report(Report& r, const Dataset& d, std::string_view leaf) {
  if (leaf == N::kReportVertices && d.shape.size() == 1 && d.data.index() == 1) {
    r.vertices = array_of<uint32_t>(d);
    return true;
  }
  if (!is_row(d) || leaf.empty()) return false;
  r.rows.push_back(row_of(d, std::string(leaf)));
  return true;
}

template <class T> T* find_named(std::vector<T>& list, std::string_view name) {
  for (T& x : list)
    if (x.name == name) return &x;
  return nullptr;
}
template <class T> T& named(std::vector<T>& list, std::string_view name) {
  if (T* x = find_named(list, name)) return *x;
  list.emplace_back().name = std::string(name);
  return list.back();
}

std::string_view after(std::string_view path, std::string_view prefix) {
  return path.starts_with(prefix) ? path.substr(prefix.size()) : std::string_view();
}

// Positions as the model holds them (positions_data's inverse): float32 widened exactly, or float64.
Array<double> positions_of(const Dataset& d) {
  if (const auto* f = std::get_if<std::vector<float>>(&d.data)) return {{f->begin(), f->end()}, d.attrs};
  return array_of<double>(d);
}

// Puts `d` into the product of `s` its kind names; false when it is no product of S.
template <class S> bool take_product(S& s, std::span<const ProductSlot<S>> slots, DatasetKind kind, const Dataset& d) {
  for (const ProductSlot<S>& slot : slots)
    if (slot.kind == kind) {
      s.*slot.member = product_of(d);
      return true;
    }
  return false;
}

void take_lightmap_dataset(Lightmap& m, DatasetKind kind, const Dataset& d) {
  m.height = d.shape[0], m.width = d.shape[1];  // every lightmap dataset runs along [H, W] (validate)
  switch (kind) {
  case DatasetKind::lightmap_state:
    m.state.values = values<uint8_t>(d);
    take_attrs<Lightmap>(m, kStateFields, d.attrs, m.state.extra);
    break;
  case DatasetKind::lightmap_positions: m.positions = positions_of(d); break;
  case DatasetKind::lightmap_normals: m.normals = array_of<float>(d); break;
  default: take_product<Lightmap>(m, kTexelProducts, kind, d);
  }
}

void take_vertex_dataset(VertexSet& s, DatasetKind kind, const Dataset& d) {
  switch (kind) {
  case DatasetKind::positions: s.positions = positions_of(d); break;
  case DatasetKind::normals:
    s.normals.emplace().values = values<float>(d);
    take_attrs<Normals>(*s.normals, kNormalsFields, d.attrs, s.normals->extra);
    break;
  case DatasetKind::triangles: s.triangles = array_of<uint32_t>(d); break;
  case DatasetKind::source_position: s.source_position = array_of<uint32_t>(d); break;
  case DatasetKind::uv:
    s.uv.emplace().values = values<float>(d);
    take_attrs<Uvs>(*s.uv, kUvFields, d.attrs, s.uv->extra);
    break;
  default:
    if (take_product<VertexSet>(s, kVertexProducts, kind, d)) break;
    if (is_lightmap_kind(kind)) take_lightmap_dataset(s.lightmap ? *s.lightmap : s.lightmap.emplace(), kind, d);
  }
}

} // namespace

const SceneObject* Asset::find_object(std::string_view name) const noexcept {
  for (const SceneObject& o : objects)
    if (o.name == name) return &o;
  return nullptr;
}

const Occluder* Asset::find_occluder(std::string_view name) const noexcept {
  for (const Occluder& o : occluders)
    if (o.name == name) return &o;
  return nullptr;
}

const Light* Asset::find_light(std::string_view name) const noexcept {
  for (const Light& l : lights)
    if (l.name == name) return &l;
  return nullptr;
}

const SceneObject* Asset::find_object_by_label(std::string_view name) const noexcept {
  for (const SceneObject& o : objects)
    if (names_object(name, o.name, o.node_path)) return &o;
  return nullptr;
}

std::string object_label(std::string_view stored_name, const std::optional<std::string>& node_path) {
  return node_path && !node_path->empty() ? *node_path : std::string(stored_name);
}

bool names_object(std::string_view query, std::string_view stored_name, const std::optional<std::string>& node_path) {
  if (query == stored_name || (node_path && query == *node_path)) return true;
  if (query.find('/') == std::string_view::npos || query.size() != stored_name.size()) return false;
  for (std::size_t i = 0; i < query.size(); ++i)
    if ((query[i] == '/' ? '|' : query[i]) != stored_name[i]) return false;
  return true;
}

std::vector<Attr> shells_attrs(const Occluder& o) { return attrs_of<Occluder>(o, kShellsFields, o.extra); }

File to_file(const Asset& a) {
  File f;
  f.root_attrs = attrs_of<RootInfo>(a.root, kRootFields, a.root.extra);
  add_vertex_set(f, "", std::string(N::kReport), a.vertices);
  for (const SceneObject& o : a.objects) {
    add_vertex_set(f, object_prefix(o.name), object_report_dir(o.name), o.set);
    if (const Occluder* occ = a.find_occluder(o.name)) add_occluder(f, *occ);
  }
  if (a.fiv_environment)
    add_array(f, std::string(N::kFivEnvironment), {3, 3},
              std::vector<float>(a.fiv_environment->f_env.begin(), a.fiv_environment->f_env.end()),
              attrs_of<FivEnvironment>(*a.fiv_environment, kFivEnvironmentFields, a.fiv_environment->extra));
  if (a.irradiance_cube) {
    const auto S = uint64_t(a.irradiance_cube->size);
    add_array(f, std::string(N::kIrradianceCube), {6, S, S, 3}, a.irradiance_cube->values,
              attrs_of<IrradianceCube>(*a.irradiance_cube, kCubeFields, a.irradiance_cube->extra));
  }
  for (const Occluder& occ : a.occluders)
    if (a.find_object(occ.name) == nullptr) add_occluder(f, occ);
  for (const Light& l : a.lights) add_light(f, l);
  f.datasets.insert(f.datasets.end(), a.other_reports.begin(), a.other_reports.end());

  if (a.scene) f.group_attrs.emplace_back(std::string(N::kScene), attrs_of<SceneInfo>(*a.scene, kSceneFields, a.scene->extra));
  for (const SceneObject& o : a.objects) {
    std::vector<Attr> attrs = attrs_of<SceneObject>(o, kObjectFields, o.extra);
    if (!attrs.empty()) f.group_attrs.emplace_back(object_prefix(o.name), std::move(attrs));
  }
  for (const Light& l : a.lights) f.group_attrs.emplace_back(light_dir(l.name), attrs_of<Light>(l, kLightFields, l.extra));
  f.group_attrs.insert(f.group_attrs.end(), a.group_extras.begin(), a.group_extras.end());
  // v7: an occluder's proxy, with the other attributes its group may have.
  for (const Occluder& o : a.occluders) {
    if (!o.proxy) continue;
    const std::string dir = occluder_dir(o.name);
    auto it = std::find_if(f.group_attrs.begin(), f.group_attrs.end(), [&](const auto& g) { return g.first == dir; });
    if (it == f.group_attrs.end()) it = f.group_attrs.emplace(f.group_attrs.end(), dir, std::vector<Attr>{});
    it->second.push_back({std::string(N::kProxy), *o.proxy});
  }
  if (a.target_error) {  // /report's one typed attribute, first, before its extras (if any)
    const Attr target{std::string(N::kTargetError), *a.target_error};
    auto it = std::find_if(f.group_attrs.begin(), f.group_attrs.end(), [](const auto& g) { return g.first == N::kReport; });
    if (it == f.group_attrs.end()) f.group_attrs.emplace_back(std::string(N::kReport), std::vector<Attr>{target});
    else it->second.insert(it->second.begin(), target);
  }
  return f;
}

Asset to_asset(const File& f, const std::filesystem::path& file_for_messages) {
  Asset a;
  a.skipped_attrs = f.skipped_attrs;
  std::vector<Attr> root;
  for (const Attr& at : f.root_attrs) {
    if (at.name == N::kFormatVersion && std::holds_alternative<int64_t>(at.value))
      a.root.format_version = std::get<int64_t>(at.value);
    else if (at.name != N::kFormat)
      root.push_back(at);
  }
  take_attrs<RootInfo>(a.root, kRootFields, root, a.root.extra);

  const std::string objects_dir = cat(N::kObjects, "/"), occluders_dir = cat(N::kOccluders, "/"),
                    lights_dir = cat(N::kLights, "/");
  std::vector<const Dataset*> reports;
  for (const Dataset& d : f.datasets) {
    const DatasetKind kind = dataset_kind(d.path);
    switch (kind) {
    case DatasetKind::fiv_environment: {
      FivEnvironment& e = a.fiv_environment.emplace();
      std::copy_n(values<float>(d).begin(), 9, e.f_env.begin());
      take_attrs<FivEnvironment>(e, kFivEnvironmentFields, d.attrs, e.extra);
      break;
    }
    case DatasetKind::irradiance_cube: {
      IrradianceCube& c = a.irradiance_cube.emplace();
      c.size = int(d.shape[1]);
      c.values = values<float>(d);
      take_attrs<IrradianceCube>(c, kCubeFields, d.attrs, c.extra);
      break;
    }
    case DatasetKind::occluder_self_band1: {
      const std::string_view rest = after(d.path, occluders_dir);
      Occluder& o = named(a.occluders, rest.substr(0, rest.find('/')));
      o.self_band1.emplace().values = values<float>(d);
      take_attrs<OccluderSelfBand1>(*o.self_band1, kSelfBand1Fields, d.attrs, o.self_band1->extra);
      break;
    }
    case DatasetKind::occluder_surface_radius: {
      const std::string_view rest = after(d.path, occluders_dir);
      Occluder& o = named(a.occluders, rest.substr(0, rest.find('/')));
      o.surface_radius.emplace().values = values<float>(d);
      take_attrs<OccluderSurfaceRadius>(*o.surface_radius, kSurfaceRadiusFields, d.attrs, o.surface_radius->extra);
      break;
    }
    case DatasetKind::occluder_shells:
    case DatasetKind::occluder_valid:
    case DatasetKind::occluder_cones: {
      const std::string_view rest = after(d.path, occluders_dir);
      Occluder& o = named(a.occluders, rest.substr(0, rest.find('/')));
      if (kind == DatasetKind::occluder_cones) {
        OccluderCones& cones = o.cones.emplace();
        cones.values = float_values(d, cones.float16);
        take_attrs<OccluderCones>(*o.cones, kConesFields, d.attrs, o.cones->extra);
        break;
      }
      if (kind == DatasetKind::occluder_valid) {
        o.valid.emplace().values = values<uint8_t>(d);
        take_attrs<OccluderValid>(*o.valid, kValidFields, d.attrs, o.valid->extra);
        break;
      }
      o.n_rho = int(d.shape[0]), o.n_theta = int(d.shape[1]), o.n_phi = int(d.shape[2]);
      o.shells = float_values(d, o.float16);
      take_attrs<Occluder>(o, kShellsFields, d.attrs, o.extra);
      break;
    }
    case DatasetKind::light_vertices:
    case DatasetKind::light_face_sizes:
    case DatasetKind::light_face_indices: {
      const std::string_view rest = after(d.path, lights_dir);
      Light& l = named(a.lights, rest.substr(0, rest.find('/')));
      if (kind == DatasetKind::light_vertices) l.vertices = array_of<double>(d);
      else if (kind == DatasetKind::light_face_sizes) l.face_sizes = array_of<uint32_t>(d);
      else l.face_indices = array_of<uint32_t>(d);
      break;
    }
    case DatasetKind::report: reports.push_back(&d); break;
    case DatasetKind::unknown:
      throw FormatError(file_for_messages.string(), "unknown dataset path '" + d.path + "'");
    default: {
      const std::string prefix = vertex_set_of(d.path);
      VertexSet& s = prefix.empty() ? a.vertices : named(a.objects, after(prefix, objects_dir)).set;
      take_vertex_dataset(s, kind, d);
    }
    }
  }
  for (const auto& [group, attrs] : f.group_attrs) {
    const std::string_view object = after(group, objects_dir);
    const std::string_view light = after(group, lights_dir);
    if (group == N::kScene) {
      SceneInfo& s = a.scene.emplace();
      take_attrs<SceneInfo>(s, kSceneFields, attrs, s.extra);
    } else if (!object.empty() && object.find('/') == std::string_view::npos) {
      SceneObject& o = named(a.objects, object);
      take_attrs<SceneObject>(o, kObjectFields, attrs, o.extra);
    } else if (!light.empty() && light.find('/') == std::string_view::npos) {
      Light& l = named(a.lights, light);
      take_attrs<Light>(l, kLightFields, attrs, l.extra);
    } else if (const std::string_view occluder = after(group, occluders_dir);
               !occluder.empty() && occluder.find('/') == std::string_view::npos && find_attr(attrs, N::kProxy) != nullptr) {
      Occluder& o = named(a.occluders, occluder);
      ExtraAttrs rest;
      for (const Attr& at : attrs)
        if (at.name == N::kProxy && std::holds_alternative<std::string>(at.value)) o.proxy = std::get<std::string>(at.value);
        else rest.push_back(at);
      if (!rest.empty()) a.group_extras.emplace_back(group, std::move(rest));
    } else if (group == N::kReport) {
      ExtraAttrs rest;
      for (const Attr& at : attrs)
        if (at.name == N::kTargetError && std::holds_alternative<double>(at.value)) a.target_error = std::get<double>(at.value);
        else rest.push_back(at);
      if (!rest.empty()) a.group_extras.emplace_back(group, std::move(rest));
    } else {
      a.group_extras.emplace_back(group, attrs);
    }
  }
  // Reports last: they belong to the objects and occluders found above.
  const std::string report_dir = cat(N::kReport, "/"), object_reports = cat(N::kReport, objects_dir),
                    fiv_reports = cat(N::kReportFiv, "/");
  for (const Dataset* d : reports) {
    const std::string_view object = after(d->path, object_reports);
    const std::string_view fiv = after(d->path, fiv_reports);
    const std::size_t slash = object.find('/');
    SceneObject* o = slash == std::string_view::npos ? nullptr : find_named(a.objects, object.substr(0, slash));
    Occluder* occ = fiv.find('/') == std::string_view::npos ? find_named(a.occluders, fiv) : nullptr;
    bool taken = false;
    if (o != nullptr) taken = take_report(o->set.report, *d, object.substr(slash + 1));
    else if (occ != nullptr && is_row(*d)) {
      occ->report = row_of(*d, std::string(fiv));
      taken = true;
    } else {
      taken = take_report(a.vertices.report, *d, after(d->path, report_dir));
    }
    if (!taken) a.other_reports.push_back(*d);
  }
  auto by_name = [](const auto& x, const auto& y) { return x.name < y.name; };
  std::sort(a.objects.begin(), a.objects.end(), by_name);
  std::sort(a.occluders.begin(), a.occluders.end(), by_name);
  std::sort(a.lights.begin(), a.lights.end(), by_name);
  return a;
}

void write_asset(const std::filesystem::path& path, const Asset& asset) { write_file(path, to_file(asset)); }

Asset read_asset(const std::filesystem::path& path) { return to_asset(read_file(path), path); }

Inspection inspect_asset(const std::filesystem::path& path) {
  Inspection out;
  out.file = read_file(path, ReadCheck::header);
  try {
    validate(out.file, path);
    out.asset = to_asset(out.file, path);
  } catch (const FormatError& e) {
    out.schema_error = e.defect();
  }
  return out;
}

} // namespace prt::formats
