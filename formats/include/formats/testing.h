// formats/testing.h — for tests of readers only (hostile-input tests of read_file, the runtime
// loader, prtdump): write files that the real writer refuses to write. Never use in tools.
#pragma once

#include <formats/prtfile.h>

namespace prt::formats::testing {

// Writes `file` like write_file (same layout, filters, temp file + rename) but WITHOUT the
// schema check and WITHOUT adding "format"/"format_version": root_attrs are written verbatim, so
// a test can make a newer-version file, a non-prtbake file, a file with NaNs or bad shapes.
// Still refuses what would be memory-unsafe (data size != product(shape), rank outside 1..32).
void write_file_unvalidated(const std::filesystem::path& final_path, const File& file);

} // namespace prt::formats::testing
