// tools/prtbake/choice_text.h — what prtbake prints about a --target-error bake
// (bake/choose.h): the pilot's measurements, each integrator's prediction and the choice, then,
// after the bake, whether the error report met the target.
#pragma once

#include <bake/choose.h>
#include <bake/vertex_bake.h>

#include <string>

namespace prt::tool {

// The pilot table and the chosen integrator, to stdout. `label` prefixes every line ("" for a
// vertex bake, "object NAME: " in a scene).
void print_choice(const bake::IntegratorChoice& choice, const std::string& label = "");

// One line per product: its error in the target's units against the target, "met" or "NOT met"
// (with the reference's own noise, which the measured RMSE includes).
void print_target_check(const bake::ErrorReport& report, double target, const std::string& label = "");

} // namespace prt::tool
