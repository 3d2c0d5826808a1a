// Byte flips in place, for the hostile-input tests of the .prt.h5 reader and the loader: rewriting
// a whole file per flip costs more than the read that follows it.
#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>

namespace prt::testing {

// For each offset `at` of `offsets`: XOR the byte at `at` of `file` with `mask`, call
// `read(at)`, restore the byte. The file is otherwise untouched.
template <class Offsets, class Read>
void for_each_flipped_byte(const std::filesystem::path& file, const Offsets& offsets, unsigned char mask, Read&& read) {
  std::fstream io(file, std::ios::binary | std::ios::in | std::ios::out);
  for (const std::size_t at : offsets) {
    char c;
    io.seekg(static_cast<std::streamoff>(at));
    io.get(c);
    const auto put = [&](char v) {
      io.seekp(static_cast<std::streamoff>(at));
      io.put(v);
      io.flush();
    };
    put(static_cast<char>(c ^ static_cast<char>(mask)));
    read(at);
    put(c);
  }
}

} // namespace prt::testing
