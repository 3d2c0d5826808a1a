// test_chunk_filters.cpp — the writer filters chunks itself (formats/src/chunk_filters.h: shuffle →
// libdeflate → Fletcher-32, written with H5Dwrite_chunk, in parallel). Checked against HDF5's own
// filters on the same bytes: the shuffle's layout and the Fletcher-32 word for word; every chunk of
// a file decodes to the same bytes (padding included) as the chunk HDF5's pipeline stores; the
// file reads back through HDF5's filters (which verify the checksums); the bytes do not depend on
// the thread count.
#include "chunk_filters.h"
#include "scratch.h"

#include <formats/prtfile.h>
#include <formats/testing.h>

#include <gtest/gtest.h>
#include <hdf5.h>
#include <tbb/global_control.h>
#include <zlib.h>

#include <cstring>
#include <fstream>
#include <random>

namespace fs = std::filesystem;
namespace F = prt::formats;
namespace D = prt::formats::detail;

namespace {

std::vector<std::byte> as_bytes(const std::vector<uint8_t>& v) {
  std::vector<std::byte> out(v.size());
  std::memcpy(out.data(), v.data(), v.size());
  return out;
}

// Writes `data` as one dataset "/d" of one chunk, elements of `element_size` bytes (uint8, or
// opaque: HDF5 shuffles by the element size), filtered by HDF5 with `set_filters`, and returns
// that chunk as stored. `data` holds a whole number of elements.
template <class SetFilters>
std::vector<std::byte> library_chunk(const fs::path& path, const std::vector<uint8_t>& data, unsigned element_size,
                                     SetFilters set_filters) {
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t type = element_size == 1 ? H5Tcopy(H5T_STD_U8LE) : H5Tcreate(H5T_OPAQUE, element_size);
  const hsize_t n = data.size() / element_size;
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  H5Pset_chunk(dcpl, 1, &n);
  set_filters(dcpl);
  const hid_t ds = H5Dcreate2(f, "/d", type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  EXPECT_GE(H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), 0);
  H5Dflush(ds);
  const hsize_t origin = 0;
  hsize_t bytes = 0;
  EXPECT_GE(H5Dget_chunk_storage_size(ds, &origin, &bytes), 0);
  std::vector<std::byte> chunk(bytes);
  uint32_t mask = 0;
  EXPECT_GE(H5Dread_chunk(ds, H5P_DEFAULT, &origin, &mask, chunk.data()), 0);
  EXPECT_EQ(mask, 0u);
  H5Dclose(ds), H5Pclose(dcpl), H5Sclose(space), H5Tclose(type), H5Fclose(f);
  return chunk;
}

uint32_t stored_fletcher(const std::vector<std::byte>& chunk) {
  uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = v << 8 | std::to_integer<uint32_t>(chunk[chunk.size() - 4 + size_t(k)]);
  return v;
}

TEST(ChunkFilters, Fletcher32IsHdf5sOnOddEvenBlockAndSaturatedLengths) {
  const fs::path dir = prt::testing::fresh_dir("chunk_filters", "fletcher");
  std::mt19937 rng(7);
  // Odd lengths (the half word), HDF5's 360-word reduction blocks and their edges, runs of 0xff
  // (sums at 65535, the value that stands for 0 mod 65535) and zeros (a zero sum stays 0).
  for (const size_t n : {1u, 2u, 3u, 719u, 720u, 721u, 722u, 1441u, 65537u, 262144u}) {
    for (const int pattern : {0, 1, 2}) {
      std::vector<uint8_t> data(n);
      for (auto& b : data) b = pattern == 0 ? uint8_t(rng()) : pattern == 1 ? 0xff : 0x00;
      const std::vector<std::byte> chunk =
          library_chunk(dir / "f.h5", data, 1, [](hid_t dcpl) { H5Pset_fletcher32(dcpl); });
      ASSERT_EQ(chunk.size(), n + 4);
      EXPECT_EQ(D::fletcher32(as_bytes(data)), stored_fletcher(chunk)) << "length " << n << ", pattern " << pattern;
      EXPECT_EQ(0, std::memcmp(chunk.data(), data.data(), n));
    }
  }
}

TEST(ChunkFilters, ShuffleIsHdf5sForEveryElementSizeWithATail) {
  const fs::path dir = prt::testing::fresh_dir("chunk_filters", "shuffle");
  std::mt19937 rng(11);
  std::vector<uint8_t> data(4099);  // not a multiple of 2, 4 or 8: a tail stays in place
  for (auto& b : data) b = uint8_t(rng());
  for (const unsigned size : {1u, 2u, 4u, 8u}) {
    const std::vector<uint8_t> whole(data.begin(), data.begin() + long(data.size() / size * size));
    const std::vector<std::byte> stored =
        library_chunk(dir / "s.h5", whole, size, [](hid_t dcpl) { H5Pset_shuffle(dcpl); });
    const std::vector<std::byte> in = as_bytes(whole);
    std::vector<std::byte> ours(in.size());
    D::shuffle_bytes(in, size, ours);
    EXPECT_EQ(ours, stored) << "element size " << size;
  }
  // The tail past the last whole element is copied as is.
  const std::vector<std::byte> in = as_bytes(data);
  std::vector<std::byte> out(in.size());
  D::shuffle_bytes(in, 4, out);
  EXPECT_EQ(out.back(), in.back());
  EXPECT_EQ(out[1024], in[1]);  // byte 1 of element 0 opens the second plane of 1024 elements
}

// A file with every element type and chunk shapes that leave partial chunks at the array's end.
F::File mixed_file() {
  std::mt19937 rng(3);
  std::normal_distribution<float> g(0.f, 1.f);
  F::File f;
  f.root_attrs.push_back({"format", std::string("chunk filter test")});
  const auto floats = [&](size_t n) {
    std::vector<float> v(n);
    for (auto& x : v) x = g(rng);
    return v;
  };
  f.datasets.push_back({"/a/shells", {5, 65, 128, 3, 3}, floats(5 * 65 * 128 * 9), {}});  // [1,14,128,3,3] chunks
  f.datasets.push_back({"/a/rows", {20011, 3}, floats(20011 * 3), {}});                   // 5461-row chunks
  f.datasets.push_back({"/a/small", {7, 3}, floats(21), {}});                             // one whole chunk
  std::vector<uint8_t> mask(300001);
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = uint8_t((i / 37) % 3 == 0);
  f.datasets.push_back({"/b/mask", {300001}, mask, {}});
  std::vector<uint32_t> tri(3 * 9001);
  for (size_t i = 0; i < tri.size(); ++i) tri[i] = uint32_t(i * 2654435761u % 9001u);
  f.datasets.push_back({"/b/triangles", {9001, 3}, tri, {}});
  std::vector<double> d(4099 * 4);
  for (auto& x : d) x = double(g(rng)) * 1e-3;
  f.datasets.push_back({"/b/doubles", {4099, 4}, d, {}});
  return f;
}

// A stored chunk of ours or HDF5's, decoded: its Fletcher-32 checked, inflated by zlib, unshuffled.
std::vector<std::byte> decode(const std::vector<std::byte>& stored, size_t raw_bytes, size_t element_size) {
  EXPECT_EQ(D::fletcher32(std::span(stored).first(stored.size() - 4)), stored_fletcher(stored));
  std::vector<std::byte> shuffled(raw_bytes);
  uLongf n = raw_bytes;
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(shuffled.data()), &n, reinterpret_cast<const Bytef*>(stored.data()),
                       uLong(stored.size() - 4)),
            Z_OK);
  EXPECT_EQ(n, raw_bytes);
  std::vector<std::byte> out(raw_bytes);
  const size_t count = raw_bytes / element_size;
  for (size_t j = 0; j < element_size; ++j)
    for (size_t i = 0; i < count; ++i) out[i * element_size + j] = shuffled[j * count + i];
  return out;
}

// Every chunk of dataset `d` in both files: decoded, the same bytes; and `d` read back from ours
// through HDF5's own filters (inflate, Fletcher-32 verified). Returns the chunk count.
size_t compare_chunks(const fs::path& ours, const fs::path& library, const F::Dataset& d) {
  const std::string& path = d.path;
  const hid_t fa = H5Fopen(ours.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t fb = H5Fopen(library.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t da = H5Dopen2(fa, path.c_str(), H5P_DEFAULT), db = H5Dopen2(fb, path.c_str(), H5P_DEFAULT);
  const hid_t dcpl = H5Dget_create_plist(da);
  const hid_t type = H5Dget_type(da);
  const size_t element_size = H5Tget_size(type);
  const hid_t space = H5Dget_space(da);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(static_cast<size_t>(rank)), chunk(static_cast<size_t>(rank));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  H5Pget_chunk(dcpl, rank, chunk.data());
  EXPECT_EQ(H5Pget_nfilters(dcpl), 3);  // shuffle, deflate, fletcher32, as declared
  size_t raw_bytes = element_size;
  for (const hsize_t c : chunk) raw_bytes *= c;
  hsize_t count_a = 0, count_b = 0;
  EXPECT_GE(H5Dget_num_chunks(da, space, &count_a), 0);
  EXPECT_GE(H5Dget_num_chunks(db, space, &count_b), 0);
  EXPECT_EQ(count_a, count_b);
  for (hsize_t k = 0; k < count_a; ++k) {
    std::vector<hsize_t> offset(static_cast<size_t>(rank));
    uint32_t mask = 0;
    haddr_t addr = 0;
    hsize_t size_a = 0, size_b = 0;
    EXPECT_GE(H5Dget_chunk_info(da, space, k, offset.data(), &mask, &addr, &size_a), 0);
    EXPECT_EQ(mask, 0u);
    H5Dget_chunk_storage_size(db, offset.data(), &size_b);
    std::vector<std::byte> a(size_a), b(size_b);
    EXPECT_GE(H5Dread_chunk(da, H5P_DEFAULT, offset.data(), &mask, a.data()), 0);
    EXPECT_GE(H5Dread_chunk(db, H5P_DEFAULT, offset.data(), &mask, b.data()), 0);
    EXPECT_EQ(decode(a, raw_bytes, element_size), decode(b, raw_bytes, element_size)) << path << " chunk " << k;
  }
  std::vector<std::byte> expected, back;
  std::visit([&](const auto& v) {
    expected.resize(v.size() * sizeof v[0]);
    std::memcpy(expected.data(), v.data(), expected.size());
  }, d.data);
  back.resize(expected.size());
  EXPECT_GE(H5Dread(da, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, back.data()), 0) << path;  // file type = memory's (LE)
  EXPECT_EQ(back, expected) << path;
  H5Sclose(space), H5Tclose(type), H5Pclose(dcpl), H5Dclose(da), H5Dclose(db), H5Fclose(fa), H5Fclose(fb);
  return size_t(count_a);
}

std::string file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary | std::ios::ate);
  std::string bytes(size_t(in.tellg()), '\0');
  in.seekg(0);
  in.read(bytes.data(), std::streamsize(bytes.size()));
  return bytes;
}

TEST(ChunkFilters, EveryChunkDecodesToHdf5sChunkAndTheDatasetsReadBack) {
  const fs::path dir = prt::testing::fresh_dir("chunk_filters", "file");
  const F::File f = mixed_file();
  F::testing::write_file_unvalidated(dir / "ours.h5", f);
  F::testing::write_file_library_filters(dir / "library.h5", f);
  size_t chunks = 0;
  for (const F::Dataset& d : f.datasets) chunks += compare_chunks(dir / "ours.h5", dir / "library.h5", d);
  // 5·5 shell chunks (14 of 65 rows) + 4 of 5461 rows + 1 + 5 mask chunks (65,536 bytes each)
  // + 2 triangle chunks (5461 rows) + 3 of 2048 rows of doubles.
  EXPECT_EQ(chunks, 25u + 4u + 1u + 5u + 2u + 3u);
}

TEST(ChunkFilters, TheBytesDoNotDependOnTheThreadCount) {
  const fs::path dir = prt::testing::fresh_dir("chunk_filters", "threads");
  const F::File f = mixed_file();
  std::string first;
  for (const size_t threads : {1u, 2u, 4u}) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    F::testing::write_file_unvalidated(dir / "t.h5", f);
    const std::string bytes = file_bytes(dir / "t.h5");
    if (first.empty()) first = bytes;
    EXPECT_TRUE(bytes == first) << threads << " threads";
  }
}

} // namespace
