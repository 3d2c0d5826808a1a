// schema_refusal.h — for tests of the schema (formats/prtfile.h validate()): a File it must
// refuse, with a message that names the file and says what is wrong.
#pragma once

#include <formats/names.h>
#include <formats/prtfile.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <string_view>

namespace prt::testing {

// validate() of `f` must throw a FormatError "<file>: <defect>" whose message contains `part`.
inline void expect_refused(const formats::File& f, const std::string& part) {
  const std::string file = "refused.prt.h5";
  try {
    formats::validate(f, file);
    ADD_FAILURE() << "accepted; expected a refusal containing '" << part << "'";
  } catch (const formats::FormatError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind(file + ": ", 0), 0u) << e.what();
  }
}

// The dataset at `path` of `f`, for a test to damage (a failure, and the first dataset, when absent).
inline formats::Dataset& dataset(formats::File& f, std::string_view path) {
  for (formats::Dataset& d : f.datasets)
    if (d.path == path) return d;
  ADD_FAILURE() << "no dataset " << path;
  return f.datasets.front();
}

// `f` with the root attribute format_version `v` (validate() takes the schema version from it).
inline formats::File with_version(formats::File f, int64_t v) {
  f.root_attrs.push_back({std::string(formats::names::kFormatVersion), v});
  return f;
}

} // namespace prt::testing
