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

} // namespace prt::tool
