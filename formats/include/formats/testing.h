// formats/testing.h — for tests only: files that the real writer refuses to write (hostile-input
// tests of read_file, the runtime loader, prtdump), and the writer's slow reference (HDF5's own
// filters). Never use in tools.
#pragma once

#include <formats/prtfile.h>

namespace prt::formats::testing {

// Writes `file` like write_file (same layout, filters, temp file + rename) but WITHOUT the
// schema check and WITHOUT adding "format"/"format_version": root_attrs are written verbatim, so
// a test can make a newer-version file, a non-prtbake file, a file with NaNs or bad shapes.
// Still refuses what would be memory-unsafe (data size != product(shape), rank outside 1..32).
void write_file_unvalidated(const std::filesystem::path& final_path, const File& file);

// As write_file_unvalidated, in HDF5's oldest on-disk format, as HDF5 writes by default and as
// other tools (h5py, h5py-era scripts) do: superblock version 0, version-1 object headers,
// symbol-table groups, version-1 B-tree chunk indexes, no fletcher32: no checksum anywhere.
// `objects_only`: the same objects under a checksummed version-2 superblock (HDF5 writes that for
// a non-default file-space setting), the case a superblock check alone would let through.
// read_file refuses both (prtfile.h, "Which files the reader opens").
enum class OldestFormat { everywhere, objects_only };
void write_file_oldest_format(const std::filesystem::path& final_path, const File& file,
                              OldestFormat which = OldestFormat::everywhere);

// The reference for the writer's own filtering (parallel shuffle → deflate → Fletcher-32 with direct
// chunk writes): write_file_unvalidated's file, with the same layout, but each chunk filtered by
// HDF5's built-in pipeline (H5Dwrite, zlib). The datasets read back the same; the deflate streams
// differ.
void write_file_library_filters(const std::filesystem::path& final_path, const File& file);

} // namespace prt::formats::testing
