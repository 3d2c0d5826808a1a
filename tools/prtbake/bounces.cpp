#include "bounces.h"

#include "bakefile.h"
#include "output.h"

#include <cstdio>
#include <utility>

namespace prt::tool {

ReceiverBounces::ReceiverBounces(const Args& a, size_t triangles) : albedo_rgb_(a.albedo) {
  spec_.bounces = a.bounces;
  spec_.rays = a.bounce_rays ? a.bounce_rays : bake::BounceSpec::kDefaultRays;
  spec_.seed = a.integrator.seed;
  bake::Albedo rgb{0, 0, 0};
  for (size_t c = 0; c < 3 && c < a.albedo.size(); ++c) rgb[c] = a.albedo[c];
  albedo_.assign(triangles, rgb);
}

void ReceiverBounces::bounce(const bake::BounceField& field, const bake::RayCaster& rays,
                             const bake::VertexBake& direct, std::span<const bake::ShadePoint> points,
                             const std::string& source, const RunContext& run, const char* noun) {
  if (!hits_)
    hits_ = bake::gather(rays, points, spec_, direct.layout.radiance_count > 0 || direct.layout.shadowed_count > 0,
                         run.progress);
  bake::BounceResult r = bake::bounce_rows(field, points, *hits_, albedo_, direct.layout, direct.values, spec_, source,
                                           run.progress);
  bounced_ = direct;
  bounced_->values = std::move(r.values);
  applied_ = r.applied;
  std_error_ = r.total_relative_std_error();
  if (run.say) print_bounces(r, spec_, bake::albedo_text(albedo_.empty() ? bake::Albedo{0, 0, 0} : albedo_[0]), *hits_,
                             direct.layout, noun);
}

void ReceiverBounces::set_attributes(formats::Product* transfer, formats::Product* radiance,
                                     formats::Product* shadowed) const {
  if (!bounced_) return;
  if (transfer) set_bounces(*transfer, Bounced::Transfer, applied_, spec_, albedo_rgb_, std_error_);
  if (radiance) set_bounces(*radiance, Bounced::Band1, applied_, spec_, albedo_rgb_, std_error_);
  if (shadowed) set_bounces(*shadowed, Bounced::Shadowed, applied_, spec_, albedo_rgb_, std_error_);
}

} // namespace prt::tool
