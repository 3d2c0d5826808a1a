// tools/prtbake/shards.h — sharded and resumable bakes (docs/ARCHITECTURE.md "Data path"): who
// this process is among the workers, which fixed chunks of rows it computes, and the merge that
// joins them into the one file a single-process --reproducible bake writes, byte for byte.
//
// Launchers (the engines, not a protocol of ours):
//   mpirun -n N prtbake ...     with MPI linked (PRT_MPI): rank r is worker r of N; the ranks
//                               agree after their chunks (MPI_Allreduce) and rank 0 merges.
//   prtbake ... --shard auto    a SLURM array task (SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN of
//                               SLURM_ARRAY_TASK_COUNT), else OMPI_COMM_WORLD_RANK/SIZE, else
//                               PMI_RANK/PMI_SIZE; computes its chunks only.
//   prtbake ... --shard I/N     worker I (0-based) of N; computes its chunks only.
//   prtbake ... --merge         verifies every chunk and writes the file (a dependent job).
//   prtbake ... --resume        one process: its chunks, then the merge.
// Chunks live in OUT.chunks/ (--chunks DIR), are removed after a successful merge, and are reused
// by a rerun of the same command (bake/core/chunks.h: checksummed, tagged with the bake's manifest).
// Static claiming gives worker i the chunks i, i + N, ...; dynamic claiming lets each worker take
// the next unclaimed chunk (claim files of this run, bake/core/chunks.h). A run is one launch: mpirun
// (rank 0 picks a run id and broadcasts it), a SLURM array (its job id) or --run-id; claims of
// another run are stale by definition, so a rerun recomputes what a dead run claimed.
// Vertex and texel bakes: one row set, the vertices or the valid texels of the lightmap (in texel
// order; the atlas is in the manifest).
// FIV bakes: row set 0 is the DifMap's texels, row set 1 the environment FIV (one row), row set
// 2 + k shell k's samples, each cut into slabs of rows. Where the shells stop depends on the shells themselves (bake/bake/fiv.h FivShellRows::stops_after), so workers take chunks shell
// after shell without waiting for each other and read the stopping rule from committed chunks:
// once a complete shell meets it, no worker starts a chunk beyond it. A worker ahead of the
// others may compute chunks past the last shell while that shell is not complete (about one
// chunk per worker when they keep pace); the merge evaluates the rule shell by shell from the
// chunks, as the single-process bake does, and ignores those.
// Sharded bakes are always reproducible (--reproducible is implied): the merged file cannot hold
// one wall time of many workers, and a target error's choice must be the same on every worker.
#pragma once

#include <bake/bake/vertex_bake.h>
#include <bake/core/chunks.h>
#include <bake/core/progress.h>

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace prt::tool {

enum class Claim { Static, Dynamic };

struct ShardOptions {
  bool resume = false;  // --resume
  std::string shard;    // --shard I/N or auto ("": not given)
  bool merge = false;   // --merge
  Claim claim = Claim::Static;
  uint64_t chunk_rows = 2048;
  std::string chunks_dir;  // "": OUT.chunks
  std::string run_id;      // --run-id
  std::string rerun_command;  // the command line as typed, shell-quoted: what resumes a cancelled bake
  bool given() const { return resume || !shard.empty() || merge; }
};

// --resume, --shard, --merge, --claim, --chunk-rows, --chunks, --run-id on a subcommand whose
// rows are `rows` ("vertices": what --chunk-rows counts).
void add_shard_options(CLI::App& cmd, ShardOptions& options, const std::string& rows);
// The options above that take a value (the stored command line leaves them out: they do not
// change the file).
bool is_shard_option(const std::string& name, bool& takes_value);

// MPI for the lifetime of the process when it was started by mpirun and prtbake is linked with
// MPI; otherwise inactive. Finalised on normal exit; when an error unwinds, left unfinalised so
// that mpirun ends the other ranks instead of leaving them waiting.
class MpiSession {
public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  bool active() const { return active_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  // true when every rank passes true (an inactive session returns `ok`).
  bool all(bool ok) const;
  std::string broadcast(const std::string& text) const;  // rank 0's text, on every rank

private:
  bool active_ = false;
  int rank_ = 0, size_ = 1;
};

struct Worker {
  int index = 0, count = 1;
  bool computes = true;  // false for --merge
  bool merges = true;    // writes the file after the chunks
  Claim claim = Claim::Static;
  std::string run_id;
  std::string launcher;  // how it was started, for its log lines
};
// Throws UsageError when the options do not say who this process is.
Worker resolve_worker(const ShardOptions& options, const MpiSession& mpi);

// One sharded bake's rows: row sets of `set_rows` rows, cut into chunks of options.chunk_rows.
class ShardedRows {
public:
  // `manifest`: manifest_of(...) of everything the rows depend on; set s has set_rows[s] rows of
  // set_widths[s] values.
  ShardedRows(const Worker& worker, const MpiSession& mpi, const ShardOptions& options, const std::string& output,
              const std::string& manifest, const std::vector<uint64_t>& set_rows, std::vector<uint32_t> set_widths,
              bool quiet);
  ~ShardedRows();
  // The rows [range.begin, range.end) of set range.set (`monitor` cancels on Ctrl-C): values,
  // standard errors (or none), counters and times; work() fills in the range and the width.
  using Compute = std::function<bake::ChunkData(const bake::ChunkRange&, const bake::Monitor& monitor)>;
  // The last row set the bake needs, once known (FIV shells: the first shell that meets the
  // stopping rule, read from committed chunks); nullopt while every set may be needed.
  using LastSet = std::function<std::optional<uint32_t>()>;
  // Runs `body`, which calls work() for the rows (not with --merge), then, under mpirun, waits
  // for every rank (an error in any rank stops the merge). Returns whether this process merges.
  bool run(const std::function<void()>& body);
  // Computes and commits this worker's uncommitted chunks (of set `set` only, when given; of the
  // sets up to last_set() only, asked before each chunk, when given).
  void work(const Compute& compute, std::optional<uint32_t> set = std::nullopt, const LastSet& last_set = {});
  // Whether every chunk of set `set` has been committed (not verified).
  bool complete(uint32_t set) const;
  // Every chunk of set `set`, verified (InputError naming a missing, corrupt or foreign chunk),
  // joined in row order: values (and standard errors when the chunks hold them), counters and
  // times summed.
  bake::ChunkData join(uint32_t set) const;
  // join() into `out`, its memory reused (set after set into one ChunkData: no new allocation
  // for sets of the same size); each chunk's rows are read from its file straight into place.
  void join(uint32_t set, bake::ChunkData& out) const;
  // join() as one bake of that set's rows in `layout` (its closed_form counter too).
  bake::VertexBake merge(uint32_t set, const bake::ProductLayout& layout) const;
  // After the file is written: removes the chunk directory.
  void finish() const;
  // After a cancellation (Ctrl-C): the chunks committed so far are kept for a rerun; the line
  // that says how many, where, and the command that resumes. nullopt when none was committed (the
  // chunk directory is then removed: nothing was written).
  std::optional<std::string> kept_after_cancel() const;
  // The threads one chunk's rows were computed on when every chunk of the bake was computed by
  // this process in this run (a --resume run that reused nothing); 0 when chunks come from other
  // workers or an earlier run, whose thread counts are not recorded.
  int threads_of_chunks() const;

private:
  struct State;
  std::unique_ptr<State> s_;
};

// Rows [range.begin, range.end) of `points` (bake_point_rows) with their closed-form count.
bake::ChunkData bake_chunk(std::span<const bake::ShadePoint> points, const bake::ChunkRange& range,
                           const bake::Integrator& integrator, const bake::Monitor& monitor);

// This process's CPU time in seconds, all threads (CLOCK_PROCESS_CPUTIME_ID).
double process_cpu_seconds();

// The SHA-256 of the lines that determine a bake's rows (inputs' digests, options, integrator,
// seed, chunk size).
std::string manifest_of(const std::vector<std::string>& lines);

} // namespace prt::tool
