// bake/core/chunks.h — a bake cut into fixed chunks of rows, each committed to its own checksummed
// file, so that workers on many machines (or one machine after a crash) can share a bake and a
// merge can check and join the pieces (docs/ARCHITECTURE.md "Data path", sharded bakes).
//
// Contract:
// - Chunks are fixed by the bake, not by the workers: row set s (a vertex bake's rows, a scene
//   receiver's rows) of n_s rows is cut into ceil(n_s / rows_per_chunk) ranges [begin, end) in
//   order, set after set; chunk i is the i-th range. Every row is a pure function of the inputs,
//   the seed and its global index (bake/bake/vertex_bake.h bake_point_rows), so any assignment of
//   chunks to workers gives the same numbers.
// - A chunk file holds the range, the rows ([rows][width] values and, when the bake has them,
//   standard errors), the
//   integrator's work counters over them and the bake's MANIFEST (a SHA-256 of everything the
//   rows depend on, computed by the caller), and ends with the SHA-256 of the bytes before it.
//   It is written under a temporary name, fsync'd and renamed (then the directory fsync'd): a
//   chunk file under its final name is complete, whatever happens to the writer.
// - Reading verifies the checksum, the manifest and the range, and throws InputError naming the
//   file otherwise (a flipped byte, a chunk of another bake, of another cut).
// - Claims: a worker that takes chunks dynamically creates "<chunk>.claim.<run>" with
//   O_CREAT|O_EXCL; exactly one worker of a run succeeds. Claims of other runs are ignored: a
//   rerun (a new run id) recomputes whatever a dead run claimed and never committed.
// Chunk files are a machine's native doubles: merge on machines of one byte order.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace prt::bake {

struct ChunkRange {
  uint32_t set = 0;             // which row set
  uint64_t begin = 0, end = 0;  // rows [begin, end) of that set
  uint64_t rows() const { return end - begin; }
  bool operator==(const ChunkRange&) const = default;
};

// The chunks of row sets of `set_rows[s]` rows each (0-row sets have none).
std::vector<ChunkRange> row_chunks(std::span<const uint64_t> set_rows, uint64_t rows_per_chunk);

struct ChunkData {
  ChunkRange range;
  uint32_t width = 0;
  std::vector<double> values;             // [rows][width]
  std::vector<double> std_error;          // [rows][width], or empty (a bake without errors)
  uint64_t closed_form = 0;               // IntegratorStats::closed_form over these rows
  double cpu_seconds = 0, seconds = 0;    // integrator CPU time and wall time of the chunk
};

// Whether `id` can name a run in claim file names: letters, digits, '-', '_', '.' (not empty).
bool valid_run_id(std::string_view id);

// One bake's chunk directory.
class ChunkStore {
public:
  // `manifest`: 64 hexadecimal characters; the directory is created when missing.
  ChunkStore(std::filesystem::path dir, std::string manifest, std::vector<ChunkRange> chunks);

  const std::filesystem::path& dir() const { return dir_; }
  const std::vector<ChunkRange>& chunks() const { return chunks_; }
  std::filesystem::path chunk_path(size_t index) const;

  // Whether chunk `index` has a file under its final name (not verified).
  bool committed(size_t index) const;
  size_t committed_count() const;
  // Writes chunk `index` (temporary name, fsync, rename, directory fsync). SystemError on a
  // failed write.
  void commit(size_t index, const ChunkData& data) const;
  // Chunk `index`, verified; nullopt if it was never committed. InputError naming the file if it
  // is corrupt, of another bake or of another range.
  std::optional<ChunkData> read(size_t index, uint32_t width) const;
  // read() into `out`, which holds rows of `width` values from row out.range.begin of the chunk's
  // set (out.values sized by the caller to hold this chunk's rows): the chunk's values go from
  // the file straight into their rows of out.values and, when it holds standard errors, into
  // out.std_error (sized like out.values first when smaller), with no copy on the way; its
  // counters and times are added to out's. false (out unchanged) if the chunk was never
  // committed; InputError as read(), and then this chunk's rows of `out` are unspecified.
  bool read_into(size_t index, uint32_t width, ChunkData& out) const;
  // Claims chunk `index` for run `run_id` (valid_run_id); false if a worker of the same run holds it.
  bool claim(size_t index, const std::string& run_id) const;
  // Removes this store's chunk files, claims and temporaries, then the directory if empty.
  void remove() const;

private:
  std::filesystem::path dir_;
  std::string manifest_;
  std::vector<ChunkRange> chunks_;
};

} // namespace prt::bake
