// tools/prtbake/bounces.h — the interreflections of a bake of receivers (`prtbake vertex`,
// `prtbake texel`; bake/bake/bounce.h): the spec from --bounces, --albedo, --bounce-rays; the gather
// rays cast once, after the first bake; the rows of every bake (a correction's too) bounced from
// their cached hits over the command's field (its vertices, or its lightmap's texels); the line it
// prints; the attributes the file's products get. The error check measures the direct pass (the
// rows the integrator made); the file gets the sum.
#pragma once

#include <bake/bake/bounce.h>
#include <bake/bake/vertex_bake.h>
#include <bake/mesh/shade_point.h>
#include <bake/visibility/raycast.h>
#include <formats/asset.h>

#include "args.h"
#include "commands.h"

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace prt::tool {

class ReceiverBounces {
 public:
  // `triangles`: of the mesh the gather rays meet (one albedo each, --albedo's).
  ReceiverBounces(const Args& a, size_t triangles);
  bool asked() const { return spec_.bounces > 0; }
  // Bounces `direct` (rows at `points`) over `field`; says so when run.say (rows called `noun`).
  void bounce(const bake::BounceField& field, const bake::RayCaster& rays, const bake::VertexBake& direct,
              std::span<const bake::ShadePoint> points, const std::string& source, const RunContext& run,
              const char* noun);
  // The rows to write: the bounced ones once bounce() ran, else `direct`.
  const bake::VertexBake& rows(const bake::VertexBake& direct) const { return bounced_ ? *bounced_ : direct; }
  // The bounce attributes of the products that bounced (any may be null).
  void set_attributes(formats::Product* transfer, formats::Product* radiance, formats::Product* shadowed) const;

 private:
  bake::BounceSpec spec_;
  std::vector<double> albedo_rgb_;  // --albedo
  std::vector<bake::Albedo> albedo_;  // per triangle
  std::optional<bake::GatherHits> hits_;
  std::optional<bake::VertexBake> bounced_;
  int applied_ = 0;
  double std_error_ = 0;  // BounceResult::total_relative_std_error
};

} // namespace prt::tool
