// tools/prtdump/summary.h — what `prtdump FILE` prints, as text or (--json) as one JSON object:
// the format and schema check, root attributes, the layout, the scene plan, the area lights, the
// error report, group and skipped attributes, and per-dataset statistics (formats/SCHEMA.md).
#pragma once

#include "values.h"

#include <formats/asset.h>

#include <ostream>
#include <string>

namespace prt::tool::dump {

// The summary of the file at `path` as text (`prtdump FILE`).
void summary_text(std::ostream& os, const std::string& path, const pf::Inspection& in);
// The same as one JSON object (`prtdump --json FILE`).
Json summary_json(const std::string& path, const pf::Inspection& in);

} // namespace prt::tool::dump
