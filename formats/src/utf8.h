// utf8.h (private) — UTF-8 validity, for the schema check (every string of a file is UTF-8) and
// for the reader (text read from a global heap, which has no checksum). Nothing here is public API.
#pragma once

#include <string_view>

namespace prt::formats::detail {

// True when `s` is well-formed UTF-8: no overlong forms, surrogates or code points past U+10FFFF.
bool valid_utf8(std::string_view s);

} // namespace prt::formats::detail
