// schema_refusal.h — for tests of the schema (formats/prtfile.h validate()): a File it must
// refuse, with a message that names the file and says what is wrong.
#pragma once

#include <formats/prtfile.h>

#include <gtest/gtest.h>

#include <string>

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

} // namespace prt::testing
