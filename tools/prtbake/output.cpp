// tools/prtbake/output.cpp — what prtbake prints about a bake and how it writes the file
// (contract: output.h).
#include "output.h"

#include "tool_main.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <sys/resource.h>
#include <utility>

namespace fs = std::filesystem;

namespace prt::tool {
namespace {

std::string timestamp(bool reproducible) {
  // Reproducible-builds convention: SOURCE_DATE_EPOCH pins the 'created' attribute, so the same
  // inputs give identical bytes across runs too.
  std::time_t t = std::time(nullptr);
  if (reproducible) {
    const char* e = std::getenv("SOURCE_DATE_EPOCH");
    t = e ? std::time_t(std::strtoll(e, nullptr, 10)) : 0;
  }
  char buf[32];
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// The fix for normals that point inside, as the warnings below say it.
const char* flip_fix(bool flipped) {
  return flipped ? "rerun without --flip-normals (this run flipped the mesh)" : "rerun with --flip-normals";
}

std::string human_bytes(uintmax_t b) {
  char buf[32];
  if (b >= (1u << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", double(b) / (1 << 20));
  else std::snprintf(buf, sizeof buf, "%.1f KiB", double(b) / 1024);
  return buf;
}

} // namespace

void print_warnings(const std::vector<std::string>& warnings) {
  std::vector<std::pair<std::string, size_t>> seen;
  for (const auto& w : warnings) {
    auto it = std::find_if(seen.begin(), seen.end(), [&](const auto& x) { return x.first == w; });
    if (it == seen.end()) seen.emplace_back(w, 1);
    else ++it->second;
  }
  for (const auto& [w, n] : seen)
    std::fprintf(stderr, "prtbake: warning: %s%s\n", w.c_str(), n > 1 ? (" (" + std::to_string(n) + " times)").c_str() : "");
}

void warn_inward(const bake::WindingFacts& facts, bool flipped, const std::string& object, bool casts) {
  const size_t inward = facts.inward_components();
  if (inward == 0) return;
  // --flip-normals flips the whole mesh: the fix only when everything in it is inwards.
  const std::string fix =
      !object.empty() ? std::string("fix their winding in its mesh file")
      : inward == facts.components
          ? std::string(flip_fix(flipped))
          : "fix their winding in the file (--flip-normals would flip all " + std::to_string(facts.components) +
                " components of the mesh, not only these)";
  std::fprintf(stderr,
               "prtbake: warning: %s%zu of %zu closed components (%zu triangles) are wound inwards: their normals point "
               "inside, so their vertices %s; %s\n",
               object.empty() ? "" : (object + ": ").c_str(), inward, facts.closed.size(), facts.inward_triangles(),
               casts ? "see no sky" : "are shaded as if seen from inside", fix.c_str());
}

void warn_no_sky(const bake::NoSkyCount& count, const bake::WindingFacts& facts,
                 const std::function<bake::FlipProbe()>& probe, bool flipped) {
  if (!(count.share() > 0.5)) return;
  std::string why;
  if (facts.inward_components() > 0) {
    why = "some closed parts are wound inwards (see above)";
  } else {
    const bake::FlipProbe p = probe();
    const std::string tally = std::to_string(p.would_see_sky) + " of " + std::to_string(p.probed) +
                              " sampled would see sky with the opposite normal";
    why = 2 * p.would_see_sky > p.probed
              ? tally + ", so their normals point inside the geometry; " + flip_fix(flipped)
              : tally + ", so they are enclosed by other geometry (parts inside or pushed into other parts), not "
                        "turned inside out; nothing to fix in the normals";
  }
  std::fprintf(stderr, "prtbake: warning: %.1f%% of vertices (%zu of %zu) see no sky at all: %s\n",
               100 * count.share(), count.vertices, count.total, why.c_str());
}

void warn_unreached(const bake::IntegratorChoice& choice, const std::string& object) {
  if (choice.reaches) return;
  std::fprintf(stderr,
               "prtbake: warning: %starget error %g is not reached within the chooser's bounds: baking %s at %u samples, "
               "expected error %.2g; %s (--integrator, --samples, --target-error)\n",
               object.empty() ? "" : (object + ": ").c_str(), choice.target, bake::to_string(choice.spec.kind),
               choice.spec.samples(), choice.expected_error, choice.further.c_str());
}

void print_reference_plan(const bake::ReferencePlan& plan) {
  std::printf("report reference: QMC at %u rays per point on %zu points (probe at %u rays, %.2f s); expected noise",
              plan.rays, plan.points, bake::ReferencePlan::kReportProbeRays, plan.probe_seconds);
  for (size_t p = 0; p < plan.products.size(); ++p)
    std::printf("%s %s %.1e", p ? "," : "", bake::product_label(plan.products[p]), plan.noise[p]);
  std::printf(" (E/3 = %.1e%s)\n", plan.target / 3,
              plan.budget_bound ? "; the report's ray budget keeps some product above it" : "");
}

prt::formats::RootInfo root_info(const Args& a, const std::string& source_sha) {
  prt::formats::RootInfo r;
  r.generator = std::string("prtbake ") + kToolkitVersion;
  r.created = timestamp(a.reproducible);
  r.command_line = a.command_line;
  r.source = a.input;
  r.source_sha256 = source_sha;
  r.up_axis = a.up == bake::UpAxis::Y ? "y" : "z";
  r.sh_convention = "real orthonormal SH, Condon-Shortley phase, index l*(l+1)+m, order = number of bands L (L*L "
                    "coefficients); bands 0-2 equal DirectXMath XMSHEvalDirection; directions in the mesh frame";
  return r;
}

void write_file(const Args& a, const prt::formats::Asset& asset) {
  // A Ctrl-C during a stage that takes no monitor (loading, setup, the DifMap) is honoured here:
  // a cancelled bake never writes.
  if (tool::interrupt_token().requested()) throw bake::Cancelled();
  prt::formats::write_asset(a.output, asset);
  if (!a.quiet) {
    std::error_code ec;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);  // ru_maxrss: the peak resident set, in KiB on Linux
    std::printf("wrote %s (%s); peak memory %s\n", a.output.c_str(), human_bytes(fs::file_size(a.output, ec)).c_str(),
                human_bytes(uintmax_t(usage.ru_maxrss) * 1024).c_str());
  }
}

bake::Mesh load_receiver_mesh(const Args& a, bool say) {
  bake::MeshLoadOptions mopt;
  mopt.use_file_normals = a.file_normals;
  mopt.flip_normals = a.flip_normals;
  bake::Mesh mesh = bake::load_mesh(a.input, mopt);
  print_warnings(mesh.warnings);
  if (say)
    std::printf("mesh: %s: %zu vertices, %zu triangles (%zu file positions, %zu faces), normals %s%s\n",
                a.input.c_str(), mesh.positions.size(), mesh.triangles.size(), mesh.file_positions, mesh.file_faces,
                mesh.normal_source == bake::Mesh::NormalSource::File ? "from the file" : "angle-weighted",
                a.flip_normals ? ", flipped" : "");
  if (say && mesh.origin != Eigen::Vector3d::Zero())  // far from the world origin (bake/mesh/mesh.h, ORIGIN)
    std::printf("mesh: baked relative to its origin (%.17g, %.17g, %.17g); /mesh/positions holds world coordinates\n",
                mesh.origin.x(), mesh.origin.y(), mesh.origin.z());
  return mesh;
}

std::optional<bake::EnvMap> load_environment(const Args& a, bool say) {
  std::optional<bake::EnvMap> env;
  if (a.environment.empty()) return env;
  env = bake::EnvMap::load(a.environment, a.up);
  const auto& i = env->info();
  if (say)
    std::printf("environment: %s: %dx%d %s, luminance max %.4g / mean %.4g (%.0fx), %llu negative pixel values "
                "clamped to 0 (min seen %.3g)\n",
                a.environment.c_str(), i.width, i.height, i.layout.c_str(), i.max_luminance, i.mean_luminance,
                i.mean_luminance > 0 ? i.max_luminance / i.mean_luminance : 0.0,
                (unsigned long long)i.negative_pixels_clamped, i.min_value_seen);
  return env;
}

bake::ProductRequest product_request(const Args& a, const bake::EnvMap* env) {
  bake::ProductRequest req;
  req.ao = a.ao;
  req.transfer_order = a.transfer;
  req.visibility_order = a.visibility;
  req.radiance = env;
  if (a.shadowed) req.shadowed = req.radiance, req.shadowed_order = a.shadowed;
  return req;
}

void print_baking(const Args& a, const bake::BakeJob& job, int threads) {
  std::printf("baking:");
  if (a.ao) std::printf(" ao");
  if (a.transfer) std::printf(" transfer/diffuse (order %d, %d coefficients)", a.transfer, a.transfer * a.transfer);
  if (a.visibility) std::printf(" transfer/visibility (order %d, %d coefficients)", a.visibility, a.visibility * a.visibility);
  if (!a.environment.empty()) std::printf(" radiance/band1 (3x3)");
  if (a.shadowed) std::printf(" radiance/shadowed (order %d, 3x%d)", a.shadowed, a.shadowed * a.shadowed);
  std::printf("\nintegrator: %s; %d threads; setup (ray/contour BVHs, tables) %.2f s\n", job.integrator_description.c_str(),
              threads, job.setup_seconds);
  std::fflush(stdout);
}

void print_rows_baked(const bake::BakeJob& job, bool shards_without_threads) {
  const bake::VertexBake& result = job.rows.front();
  const size_t n = job.sets.front().points.size();
  std::printf("baked %zu %s in %.2f s (%.0f integrals/s)\n", n, job.sets.front().rows_noun, result.seconds,
              double(n) / result.seconds);
  if (const std::string work = job.integrator->work_summary(); !work.empty()) std::printf("%s\n", work.c_str());
  if (shards_without_threads)
    std::printf("chunks: %.2f CPU s in the integrator over %.2f s of chunk wall time, summed over the chunks of "
                "every worker and run\n",
                result.cpu_seconds, result.seconds);
  else
    std::printf("threads busy %.0f%% of the bake (%.2f CPU s in the integrator over %.2f s on %d thread%s)\n",
                100 * result.busy_fraction(), result.cpu_seconds, result.seconds, result.threads,
                result.threads == 1 ? "" : "s");
}

void warn_inexact_texels(const bake::TexelAtlas& atlas, const std::string& who) {
  if (atlas.inexact_samples == 0) return;
  std::fprintf(stderr,
               "prtbake: warning: %s: %zu of %zu texels could not be put exactly on their triangles, nor a few "
               "roundings in front of them (corners whose coordinates differ in scale by more than 2^29, such as "
               "4e-17 beside 0.04, on a crease too thin to step out of): such a texel may see its own triangle from "
               "behind (dark); moving the mesh off the origin, or snapping coordinates that are zero up to rounding, "
               "avoids it\n",
               who.c_str(), atlas.inexact_samples, atlas.samples.size());
}

void print_bounces(const bake::BounceResult& result, const bake::BounceSpec& spec, const std::string& albedo,
                   const bake::GatherHits& hits, const bake::ProductLayout& layout, const char* noun) {
  const std::string what = layout.transfer_count && layout.radiance_count ? "diffuse transfer and band-1 radiance"
                           : layout.transfer_count                        ? "diffuse transfer"
                                                                          : "band-1 radiance";
  std::printf("bounced the %s: %d of %d bounce%s at albedo %s (each bounce's RMS / the direct pass's:", what.c_str(),
              result.applied, spec.bounces, spec.bounces == 1 ? "" : "s", albedo.c_str());
  for (const double r : result.relative_rms) std::printf(" %.3g", r);
  if (result.applied < spec.bounces)
    std::printf("; stopped early: the last one added at most %g of the direct pass's RMS", spec.tolerance);
  std::printf("); their Monte Carlo error, from the two halves of the rays: %.2g of the direct pass's RMS\n",
              result.total_relative_std_error());
  std::printf("the file holds direct + bounces; the error check measures the direct pass\n");
  double bounce_seconds = 0;
  for (const double s : result.seconds) bounce_seconds += s;
  std::printf("gather: %u rays per %s (%s) cast once in %.2f s (cached hits %.1f MB); the bounces took %.3f s "
              "(%.3f s each)\n",
              hits.rays, noun, hits.mixture ? "half cosine, half uniform" : "cosine", hits.seconds,
              double(hits.bytes()) / 1e6, bounce_seconds, result.applied ? bounce_seconds / result.applied : 0.0);
}

void print_error_report(const bake::BakeJob& job) {
  const bake::ErrorReport& report = *job.reports.front();
  std::printf("error against a %u-ray QMC reference on %zu seeded %s (reference took %.2f s, not "
              "counted in the bake time):\n",
              job.spec.reference_rays(), report.vertices.size(), job.sets.front().rows_noun, report.reference_seconds);
  // The bake's own standard error is a sampled integrator's estimate; a deterministic one
  // (silhouette: its error is a bias, which only the comparison measures) has none to print.
  const bool sampled =
      std::any_of(report.products.begin(), report.products.end(), [](const auto& e) { return e.bake_std_error > 0; });
  for (const auto& e : report.products) {
    std::printf("  %-20s RMSE %.3e  max %.3e  relative RMSE %.3e  (", bake::product_label(e.product), e.rmse, e.max_abs,
                bake::relative_scale(e) > 0 ? e.rmse / bake::relative_scale(e) : 0.0);
    if (sampled) std::printf("the bake's std. error by QMC's estimator, an upper bound, %.3e; ", e.bake_std_error);
    if (e.finer > 1)
      std::printf("against the same integrator at %.0fx its isolines, N = %u, on %zu %s: its own error at most %.3e)\n",
                  e.finer, e.finer_knob, e.finer_points, job.sets.front().rows_noun, e.reference_std_error);
    else
      std::printf("the reference's own std. error %.3e, %s)\n", e.reference_std_error,
                  report.reference_noise_measured ? "measured from its two halves" : "QMC's estimate");
  }
}

void print_error_verdict(const bake::BakeJob& job, double target) {
  const std::vector<std::string> lines =
      target > 0 ? bake::target_check_lines(*job.pooled, target, job.reference_plan ? &*job.reference_plan : nullptr)
                 : bake::error_estimate_lines(*job.pooled);
  for (const std::string& line : lines) std::printf("%s\n", line.c_str());
}

void print_generated_uvs(const std::string& who, const char* why, const std::string& set, const bake::UnwrapReport& r) {
  std::fprintf(stderr,
               "prtbake: %s: %s: generated lightmap UVs %s: %zu charts%s, utilisation %.2f, worst stretch %.2f "
               "(mean %.2f), %ux%u texels at %.4g texels per unit%s, %.1f s\n",
               who.c_str(), why, set.c_str(), r.charts,
               r.degenerate_triangles == 0
                   ? ""
                   : (" (and " + std::to_string(r.degenerate_triangles) + " zero-area triangles at UV (0, 0))").c_str(),
               r.utilisation, r.worst_stretch, r.mean_stretch, r.width, r.height, r.density,
               r.scaled_charts == 0 ? "" : (" (" + std::to_string(r.scaled_charts) + " thin charts denser, up to 4x)").c_str(),
               r.seconds);
}

void print_stitch(const bake::SeamStitch& seams, const std::string& who) {
  std::printf("%sseams: %zu UV seam edges, %zu points looked up from both sides (%zu reach an empty texel or another "
              "chart's: left out), %zu texels moved (a baked one by %.2e at most): mean |difference| %.2e -> %.2e, "
              "largest %.2e -> %.2e\n",
              who.empty() ? "" : (who + ": ").c_str(), seams.edges, seams.points, seams.skipped_points, seams.texels,
              seams.baked_moved_max, seams.mean_before, seams.mean_after, seams.max_before, seams.max_after);
}

void print_mip_check(const std::array<size_t, bake::kMipLevels + 1>& hits, const std::string& who) {
  std::string levels;
  for (size_t k = 0; k < hits.size(); ++k) levels += (k ? ", " : "") + std::to_string(hits[k]);
  std::printf("%slightmap: surface points whose bilinear lookup reaches an empty texel at mip levels 0-%d: %s%s\n",
              who.empty() ? "" : (who + ": ").c_str(), bake::kMipLevels, levels.c_str(),
              hits.back() == 0 ? "" : " (more --padding, or a larger atlas, keeps them off)");
}

void print_correction(const bake::BakeJob& job, const bake::IntegratorSpec& better) {
  std::printf("%s\n", bake::correction_text(job, better).c_str());
  std::fflush(stdout);
}

} // namespace prt::tool
