// Chunk files of sharded bakes (bake/core/chunks.h) and the row-range form of bake_points.
#include <bake/bake/vertex_bake.h>
#include <bake/core/chunks.h>
#include <bake/core/error.h>
#include <bake/mesh/mesh.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;
using namespace prt::bake;

namespace {

const std::string kManifest(64, 'a'), kOther(64, 'b');

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(PRT_TEST_TMP) / ("chunks_" + name);
  fs::remove_all(d);
  return d;
}

ChunkData sample_chunk(const ChunkRange& range, uint32_t width) {
  ChunkData d;
  d.range = range;
  d.width = width;
  for (uint64_t i = 0; i < range.rows() * width; ++i) {
    d.values.push_back(0.25 * double(i) + double(range.begin));
    d.std_error.push_back(1e-3 * double(i));
  }
  d.closed_form = 3;
  d.cpu_seconds = 0.5;
  return d;
}

} // namespace

TEST(Chunks, RowChunksCoverEverySetInOrder) {
  const std::vector<uint64_t> rows = {10, 0, 4};
  const std::vector<ChunkRange> c = row_chunks(rows, 4);
  const std::vector<ChunkRange> want = {{0, 0, 4}, {0, 4, 8}, {0, 8, 10}, {2, 0, 4}};
  EXPECT_EQ(c, want);
}

TEST(Chunks, CommitThenReadGivesTheSameRows) {
  const fs::path dir = fresh_dir("roundtrip");
  const ChunkStore store(dir, kManifest, row_chunks(std::vector<uint64_t>{7}, 3));
  ASSERT_EQ(store.chunks().size(), 3u);
  EXPECT_FALSE(store.read(1, 2).has_value());  // never committed
  const ChunkData d = sample_chunk(store.chunks()[1], 2);
  store.commit(1, d);
  EXPECT_TRUE(store.committed(1));
  EXPECT_EQ(store.committed_count(), 1u);
  const auto back = store.read(1, 2);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->values, d.values);
  EXPECT_EQ(back->std_error, d.std_error);
  EXPECT_EQ(back->closed_form, 3u);
  // No temporary left next to it.
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 1u);
  store.remove();
  EXPECT_FALSE(fs::exists(dir));
}

// A bake without standard errors (FIV shell rows) commits values only: read back without them.
TEST(Chunks, ValuesOnlyChunkReadsBackWithoutStandardErrors) {
  const fs::path dir = fresh_dir("values_only");
  const ChunkStore store(dir, kManifest, row_chunks(std::vector<uint64_t>{5}, 5));
  ChunkData d = sample_chunk(store.chunks()[0], 2);
  const ChunkData with_errors = d;
  d.std_error.clear();
  store.commit(0, d);
  const auto back = store.read(0, 2);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->values, d.values);
  EXPECT_TRUE(back->std_error.empty());
  // Half the bytes of the rows: the errors are not stored as zeros.
  const uintmax_t values_only = fs::file_size(store.chunk_path(0));
  store.commit(0, with_errors);
  EXPECT_EQ(fs::file_size(store.chunk_path(0)) - values_only, 10 * sizeof(double));
  store.remove();
}

// read_into places each chunk's rows at their rows of a buffer of the whole set and adds its
// counters: chunk after chunk into one buffer gives the set, as the chunks hold it.
TEST(Chunks, ReadIntoPlacesTheRowsOfEachChunk) {
  const fs::path dir = fresh_dir("read_into");
  const ChunkStore store(dir, kManifest, row_chunks(std::vector<uint64_t>{7}, 3));
  ChunkData out;
  out.range = {0, 0, 7};
  out.values.assign(7 * 2, -1.0);
  EXPECT_FALSE(store.read_into(2, 2, out));  // never committed: out unchanged
  EXPECT_EQ(out.values, std::vector<double>(7 * 2, -1.0));
  EXPECT_TRUE(out.std_error.empty());
  std::vector<double> values, std_error;
  for (size_t i : {size_t(2), size_t(0), size_t(1)}) store.commit(i, sample_chunk(store.chunks()[i], 2));
  for (size_t i = 0; i < 3; ++i) {
    const ChunkData d = sample_chunk(store.chunks()[i], 2);
    values.insert(values.end(), d.values.begin(), d.values.end());
    std_error.insert(std_error.end(), d.std_error.begin(), d.std_error.end());
  }
  for (size_t i : {size_t(1), size_t(2), size_t(0)}) ASSERT_TRUE(store.read_into(i, 2, out));  // any order
  EXPECT_EQ(out.values, values);
  EXPECT_EQ(out.std_error, std_error);
  EXPECT_EQ(out.closed_form, 3u * 3u);
  EXPECT_EQ(out.cpu_seconds, 3 * 0.5);
  // A buffer that starts at the chunk's own first row: read() is read_into() of such a buffer.
  ChunkData one;
  one.range = store.chunks()[1];
  one.values.resize(3 * 2);
  ASSERT_TRUE(store.read_into(1, 2, one));
  EXPECT_EQ(one.values, store.read(1, 2)->values);
  // A buffer too small for the chunk's rows is the caller's bug.
  ChunkData small;
  small.values.resize(5 * 2);
  EXPECT_THROW(store.read_into(2, 2, small), ContractError);
  store.remove();
}

TEST(Chunks, EveryFlippedByteIsRefused) {
  const fs::path dir = fresh_dir("flip");
  const ChunkStore store(dir, kManifest, row_chunks(std::vector<uint64_t>{4}, 4));
  store.commit(0, sample_chunk(store.chunks()[0], 3));
  const fs::path p = store.chunk_path(0);
  const size_t size = fs::file_size(p);
  std::string bytes(size, '\0');
  std::ifstream(p, std::ios::binary).read(bytes.data(), std::streamsize(size));
  for (size_t at = 0; at < size; at += 7) {  // every 7th byte, header, rows and digest alike
    std::string bad = bytes;
    bad[at] = char(bad[at] ^ 0x01);
    std::ofstream(p, std::ios::binary | std::ios::trunc).write(bad.data(), std::streamsize(size));
    EXPECT_THROW(store.read(0, 3), InputError) << "byte " << at;
  }
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(size / 2));
  EXPECT_THROW(store.read(0, 3), InputError) << "truncated";
}

TEST(Chunks, AnotherBakesChunkIsRefusedNamingTheFile) {
  const fs::path dir = fresh_dir("other");
  const std::vector<ChunkRange> cut = row_chunks(std::vector<uint64_t>{8}, 4);
  const ChunkStore other(dir, kOther, cut), mine(dir, kManifest, cut);
  other.commit(1, sample_chunk(cut[1], 2));
  try {
    mine.read(1, 2);
    FAIL() << "accepted another bake's chunk";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), mine.chunk_path(1).string());
    EXPECT_NE(e.defect().find("another bake"), std::string::npos) << e.what();
  }
  // The same manifest but another cut (another chunk size): refused by its range.
  const ChunkStore recut(dir, kOther, row_chunks(std::vector<uint64_t>{8}, 2));
  EXPECT_THROW(recut.read(1, 2), InputError);
  // Another width (another product layout).
  EXPECT_THROW(other.read(1, 3), InputError);
}

TEST(Chunks, OneClaimPerRunAndChunk) {
  const fs::path dir = fresh_dir("claim");
  const ChunkStore store(dir, kManifest, row_chunks(std::vector<uint64_t>{8}, 4));
  EXPECT_TRUE(store.claim(0, "run1"));
  EXPECT_FALSE(store.claim(0, "run1"));  // held by a worker of this run
  EXPECT_TRUE(store.claim(1, "run1"));
  EXPECT_TRUE(store.claim(0, "run2"));  // a new run ignores the old run's claims
  store.remove();
  EXPECT_FALSE(fs::exists(dir));
}

// Any cut into row ranges gives bake_points' rows: each row is randomised by its global index.
TEST(Chunks, RowRangesEqualTheWholeBake) {
  const Mesh mesh = load_mesh(std::string(PRT_DATA_DIR) + "/ground.obj");
  const Topology topo = build_topology(mesh);
  const std::vector<ShadePoint> points = vertex_shade_points(mesh, topo);
  ProductRequest req;
  req.ao = true;
  req.transfer_order = 2;
  IntegratorSpec spec;
  spec.kind = IntegratorKind::Qmc;
  spec.qmc_rays = 32;
  const auto integrator = make_integrator(spec, mesh, topo, req);
  const VertexBake whole = bake_points(points, *integrator);
  const size_t W = whole.layout.width, V = points.size();
  ASSERT_GT(V, 100u);
  for (const size_t cut : {size_t(1), size_t(37), V / 2, V - 1}) {
    const VertexBake a = bake_point_rows(points, 0, cut, *integrator);
    const VertexBake b = bake_point_rows(points, cut, V, *integrator);
    std::vector<double> joined = a.values;
    joined.insert(joined.end(), b.values.begin(), b.values.end());
    EXPECT_EQ(joined, whole.values) << "cut at " << cut;  // bit for bit
    EXPECT_EQ(b.std_error, std::vector<double>(whole.std_error.begin() + ptrdiff_t(cut * W), whole.std_error.end()));
  }
}
