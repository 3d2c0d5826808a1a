// tools/prtbake/output.h — what the bake commands say besides their progress and results:
// warnings about the input on stderr (each "prtbake: warning: ..."), the error report's
// reference plan; and the file they write: its root attributes, and the write itself.
#pragma once

#include <bake/bake/bounce.h>
#include <bake/bake/choose.h>
#include <bake/bake/diagnostics.h>
#include <bake/bake/lightmap.h>
#include <bake/mesh/texels.h>
#include <bake/bake/pipeline.h>
#include <bake/mesh/mesh.h>
#include <bake/mesh/unwrap.h>
#include <formats/asset.h>

#include "args.h"

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace prt::tool {

// Prints reader warnings once each, with a count for repeats.
void print_warnings(const std::vector<std::string>& warnings);

// Closed components wound inwards (bake/mesh/mesh.h winding_facts): their vertices will see no sky.
// `object`: a scene's object ("" for prtbake vertex, whose --flip-normals can fix a whole mesh).
// `casts`: the mesh shadows itself (a vertex bake, a scene's "both"), so those vertices see no sky;
// a receiver-only object casts nothing and is shaded about normals that point inside.
void warn_inward(const bake::WindingFacts& facts, bool flipped, const std::string& object = "", bool casts = true);

// More than half the vertices saw no sky at all (bake/bake/diagnostics.h count_no_sky). Which
// explanation fits: closed parts wound inwards (said above), or else the flip probe — with their
// normals reversed, would these vertices see sky (normals pointing inside: flip them) or not
// (vertices enclosed by other geometry: an engine's internals under its housing, parts pushed
// into each other; the bake is right and nothing is to be fixed)?
void warn_no_sky(const bake::NoSkyCount& count, const bake::WindingFacts& facts,
                 const std::function<bake::FlipProbe()>& probe, bool flipped);

// A target the chooser could not reach within its bounds: it baked the best plan it had
// (bake/bake/choose.h, step 5); say so on stderr, with the options that go further.
void warn_unreached(const bake::IntegratorChoice& choice, const std::string& object);
// On stderr, when a lightmap has texels whose surface point could neither be put exactly on its
// triangle nor lifted strictly in front of it (bake/mesh/texels.h TexelAtlas::inexact_samples):
// such a point may lie a rounding behind its own triangle and see it as a roof (a dark texel).
// `who`: the file or the scene object.
void warn_inexact_texels(const bake::TexelAtlas& atlas, const std::string& who);

// The error report's reference for a target (bake/bake/choose.h plan_report_reference), with -v.
void print_reference_plan(const bake::ReferencePlan& plan);

// The mesh of prtbake vertex and texel (--no-file-normals, --flip-normals), its warnings printed,
// and (with `say`) one line on it.
bake::Mesh load_receiver_mesh(const Args& a, bool say);
// --radiance's environment (none without it), and (with `say`) one line on it.
std::optional<bake::EnvMap> load_environment(const Args& a, bool say);
// The products the command line asks for (--ao, --transfer, --visibility, --radiance, --shadowed).
bake::ProductRequest product_request(const Args& a, const bake::EnvMap* env);

// What a bake of receivers (prtbake vertex, texel; bake/bake/pipeline.h) says as it goes, on
// stdout: the products and the integrator once it is made (`rows`: "vertices", "texels"); the
// rows baked, the integrator's own work and the threads' use; the error report; the target's
// verdict (without a target, the bake's own error its RMSE means); the correction. `shards_without_threads`: the rows came from chunks of other workers
// or runs, whose threads are not recorded.
void print_baking(const Args& a, const bake::BakeJob& job, int threads);
void print_rows_baked(const bake::BakeJob& job, bool shards_without_threads);
// The interreflections: the bounces applied of those asked, each one's RMS against the direct
// pass's, the gather (rays, time, the cached hits' memory) and each bounce's time.
void print_bounces(const bake::BounceResult& result, const bake::BounceSpec& spec, const std::string& albedo,
                   const bake::GatherHits& hits, const bake::ProductLayout& layout, const char* noun);
void print_error_report(const bake::BakeJob& job);
void print_error_verdict(const bake::BakeJob& job, double target);  // target 0: what the RMSE means
// The line of the mip-level check of a lightmap (bake/bake/lightmap.h mip_empty_hits).
void print_mip_check(const std::array<size_t, bake::kMipLevels + 1>& hits, const std::string& who = "");
// The line of a lightmap's stitched seams (bake/bake/lightmap.h), prefixed by `who` ("who: ") when given.
void print_stitch(const bake::SeamStitch& seams, const std::string& who = "");
// The line a generated lightmap UV set gets on stderr: who (the file, a scene object), why it was
// generated ("--unwrap", "no UV set"), its charts, utilisation, stretch and size.
void print_generated_uvs(const std::string& who, const char* why, const std::string& set, const bake::UnwrapReport& r);
void print_correction(const bake::BakeJob& job, const bake::IntegratorSpec& better);

// The root attributes every file carries (formats/SCHEMA.md).
prt::formats::RootInfo root_info(const Args& a, const std::string& source_sha);

// Writes the asset (validated, temp + rename: formats/asset.h) and says where and how big.
void write_file(const Args& a, const prt::formats::Asset& asset);

} // namespace prt::tool
