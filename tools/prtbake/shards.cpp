// shards.cpp — sharded and resumable bakes (shards.h): launchers, chunk assignment, merge.
#include "shards.h"

#include "cli.h"
#include "progress_bar.h"
#include "tool_main.h"

#include <bake/core/error.h>
#include <bake/core/sha256.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <random>
#include <thread>
#include <time.h>
#include <unistd.h>

#ifdef PRT_HAVE_MPI
#include <mpi.h>
#endif

namespace fs = std::filesystem;

namespace prt::tool {
namespace {

const char* env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : nullptr;
}

// A non-negative integer environment variable, or -1.
long env_int(const char* name) {
  const char* v = env(name);
  if (!v) return -1;
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  return end && *end == '\0' && x >= 0 ? x : -1;
}

// "I/N" with 0 <= I < N.
bool parse_shard(const std::string& text, int& index, int& count) {
  const size_t slash = text.find('/');
  if (slash == std::string::npos) return false;
  try {
    size_t a = 0, b = 0;
    index = std::stoi(text.substr(0, slash), &a);
    count = std::stoi(text.substr(slash + 1), &b);
    return a == slash && b == text.size() - slash - 1 && count >= 1 && index >= 0 && index < count;
  } catch (const std::exception&) {
    return false;
  }
}

std::string fresh_run_id() {
  std::random_device rd;
  char buf[64];
  std::snprintf(buf, sizeof buf, "r%lx-%x-%x", long(std::time(nullptr)), unsigned(getpid()), unsigned(rd()));
  return buf;
}

// Whether a launcher started this process as one of several ranks (mpirun, srun with PMI). Used
// only when prtbake links MPI (PRT_HAVE_MPI; the tools preset builds without it).
[[maybe_unused]] bool launched_by_mpirun() { return env("OMPI_COMM_WORLD_SIZE") || env("PMI_SIZE") || env("PMIX_RANK"); }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

// ---- options ----

void add_shard_options(CLI::App& cmd, ShardOptions& o, const std::string& rows) {
  const std::string group = "Sharded and resumable bakes (the file is the same bytes as --reproducible's)";
  cmd.add_flag("--resume", o.resume,
               "commit the bake in chunks to OUT.chunks/ and merge them at the end:\n"
               "rerunning the same command after a crash or Ctrl-C reuses every\n"
               "committed chunk. Under mpirun (with MPI) every rank is a worker and rank 0\n"
               "merges, without this flag.")
      ->group(group);
  cmd.add_option("--shard", o.shard,
                 "be worker I (0-based) of N: compute its chunks, commit them and stop\n"
                 "(merge with --merge). 'auto': I/N from SLURM_ARRAY_TASK_ID/COUNT, else\n"
                 "OMPI_COMM_WORLD_RANK/SIZE, else PMI_RANK/SIZE.")
      ->option_text("I/N|auto")
      ->check([](const std::string& s) -> std::string {
        int i = 0, n = 0;
        return s == "auto" || parse_shard(s, i, n) ? "" : "expects I/N with 0 <= I < N, or auto, got '" + s + "'";
      })
      ->group(group);
  cmd.add_flag("--merge", o.merge,
               "verify every committed chunk (checksum, same bake, all rows) and write\n"
               "OUT; fails naming the first bad or missing chunk.")
      ->group(group);
  cmd.add_option_function<std::string>(
         "--claim",
         [&o](const std::string& c) {
           if (c == "static") o.claim = Claim::Static;
           else if (c == "dynamic") o.claim = Claim::Dynamic;
           else throw CLI::ValidationError("--claim", "expects static or dynamic, got '" + c + "'");
         },
         "static (default): worker I takes chunks I, I+N, ...; dynamic: each\n"
         "worker claims the next free chunk (a claim file), for uneven machines.")
      ->option_text("static|dynamic")
      ->group(group);
  cmd.add_option("--chunk-rows", o.chunk_rows,
                 "rows per chunk: " + rows + " (default " +
                     std::to_string(ShardOptions{}.chunk_rows) + ");\nthe same for every worker of a bake, whatever their number.")
      ->option_text("R")
      ->check(integer_in(1, int64_t(1) << 30))
      ->group(group);
  cmd.add_option("--chunks", o.chunks_dir, "the chunk directory (default OUT.chunks), on a file system every\nworker and the merge see.")
      ->option_text("DIR")
      ->group(group);
  cmd.add_option("--run-id", o.run_id,
                 "names this launch for --claim dynamic with --shard (the same for all\n"
                 "its workers; mpirun and SLURM arrays name theirs). A rerun with another\n"
                 "id ignores the claims of the dead one.")
      ->option_text("ID")
      ->check([](const std::string& s) { return bake::valid_run_id(s) ? "" : std::string("expects letters, digits, '-', '_' or '.'"); })
      ->group(group);
}

bool is_shard_option(const std::string& name, bool& takes_value) {
  takes_value = name == "--shard" || name == "--claim" || name == "--chunk-rows" || name == "--chunks" || name == "--run-id";
  return takes_value || name == "--resume" || name == "--merge";
}

// ---- MPI ----

#ifdef PRT_HAVE_MPI
namespace {
// Waits for a non-blocking collective without spinning. Open MPI's blocking collectives poll at
// full speed, so a rank with nothing left to do (its chunks done, or none claimed) burned a core
// while it waited for the others, stealing it from a working rank whenever ranks outnumber cores
// (mpirun -n 2 on a one-chunk bake: 5.7 CPU s against 3.0 for one process). MPI_Test drives the
// collective's progress; the pause between tests grows from 0.1 ms to 20 ms, so a short wait
// stays short and a long one costs nothing.
void wait_without_spinning(MPI_Request& request) {
  std::chrono::microseconds pause{100};
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds{20000});
  }
}
} // namespace
#endif

MpiSession::MpiSession([[maybe_unused]] int& argc, [[maybe_unused]] char**& argv) {
#ifdef PRT_HAVE_MPI
  if (!launched_by_mpirun()) return;
  if (MPI_Init(&argc, &argv) != MPI_SUCCESS) throw bake::SystemError("MPI_Init failed");
  active_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
#endif
}

MpiSession::~MpiSession() {
#ifdef PRT_HAVE_MPI
  if (active_ && std::uncaught_exceptions() == 0) {
    // The ranks that return first (rank 0 merges) wait here for the rest, asleep, before
    // MPI_Finalize's own synchronisation (which spins).
    MPI_Request request;
    MPI_Ibarrier(MPI_COMM_WORLD, &request);
    wait_without_spinning(request);
    MPI_Finalize();
  }
#endif
}

bool MpiSession::all(bool ok) const {
#ifdef PRT_HAVE_MPI
  if (active_) {
    int mine = ok ? 1 : 0, every = 0;
    MPI_Request request;
    MPI_Iallreduce(&mine, &every, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD, &request);
    wait_without_spinning(request);
    return every == 1;
  }
#endif
  return ok;
}

std::string MpiSession::broadcast(const std::string& text) const {
#ifdef PRT_HAVE_MPI
  if (active_) {
    char buf[128] = {};
    text.copy(buf, sizeof buf - 1);
    MPI_Request request;
    MPI_Ibcast(buf, int(sizeof buf), MPI_CHAR, 0, MPI_COMM_WORLD, &request);
    wait_without_spinning(request);
    return buf;
  }
#endif
  return text;
}

// ---- who this process is ----

Worker resolve_worker(const ShardOptions& o, const MpiSession& mpi) {
  Worker w;
  w.claim = o.claim;
  w.run_id = o.run_id;
  if (o.merge) {
    if (!o.shard.empty() || o.resume) throw UsageError("--merge computes nothing: give it without --shard and --resume");
    if (mpi.active() && mpi.size() > 1) throw UsageError("--merge runs as one process, not under mpirun -n " + std::to_string(mpi.size()));
    w.computes = false;
    w.launcher = "merge";
    return w;
  }
  if (o.shard == "auto") {
    w.merges = false;
    if (const long id = env_int("SLURM_ARRAY_TASK_ID"), n = env_int("SLURM_ARRAY_TASK_COUNT"); id >= 0 && n > 0) {
      const long first = std::max(0L, env_int("SLURM_ARRAY_TASK_MIN"));
      w.index = int(id - first), w.count = int(n);
      w.launcher = "SLURM array task " + std::to_string(id);
      if (w.run_id.empty() && env("SLURM_ARRAY_JOB_ID")) w.run_id = std::string("slurm") + env("SLURM_ARRAY_JOB_ID");
    } else if (const long r = env_int("OMPI_COMM_WORLD_RANK"), s = env_int("OMPI_COMM_WORLD_SIZE"); r >= 0 && s > 0) {
      w.index = int(r), w.count = int(s);
      w.launcher = "Open MPI rank " + std::to_string(r);
    } else if (const long pr = env_int("PMI_RANK"), ps = env_int("PMI_SIZE"); pr >= 0 && ps > 0) {
      w.index = int(pr), w.count = int(ps);
      w.launcher = "PMI rank " + std::to_string(pr);
    } else {
      throw UsageError("--shard auto: no SLURM_ARRAY_TASK_ID/COUNT, OMPI_COMM_WORLD_RANK/SIZE or PMI_RANK/SIZE in the "
                       "environment; give --shard I/N");
    }
    if (w.index < 0 || w.index >= w.count)
      throw UsageError("--shard auto: task " + std::to_string(w.index) + " is not in 0.." + std::to_string(w.count - 1));
  } else if (!o.shard.empty()) {
    parse_shard(o.shard, w.index, w.count);
    w.merges = false;
    w.launcher = "--shard " + o.shard;
  } else if (mpi.active()) {
    w.index = mpi.rank(), w.count = mpi.size();
    w.merges = mpi.rank() == 0;
    w.launcher = "mpirun rank " + std::to_string(mpi.rank());
    w.run_id = mpi.broadcast(w.run_id.empty() ? fresh_run_id() : w.run_id);
  } else {
    w.launcher = "--resume";
  }
  if (w.run_id.empty()) {
    if (w.claim == Claim::Dynamic && w.count > 1)
      throw UsageError("--claim dynamic with " + w.launcher + ": give --run-id ID, the same for every worker of this run");
    w.run_id = fresh_run_id();  // one worker: claims only it sees
  }
  return w;
}

bake::ChunkData bake_chunk(std::span<const bake::ShadePoint> points, const bake::ChunkRange& range,
                           const bake::Integrator& integrator, const bake::Monitor& monitor) {
  bake::VertexBake rows = bake::bake_point_rows(points, range.begin, range.end, integrator, monitor);
  bake::ChunkData d;
  d.closed_form = rows.closed_form;
  d.values = std::move(rows.values);
  d.std_error = std::move(rows.std_error);
  d.cpu_seconds = rows.cpu_seconds;
  d.seconds = rows.seconds;
  return d;
}

double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::string manifest_of(const std::vector<std::string>& lines) {
  std::string text = "prtbake chunk manifest 1\n";
  for (const std::string& l : lines) text += l + "\n";
  return bake::sha256_bytes(std::span(reinterpret_cast<const std::byte*>(text.data()), text.size()));
}

// ---- the rows ----

struct ShardedRows::State {
  Worker worker;
  const MpiSession* mpi = nullptr;
  bake::ChunkStore store;
  std::vector<uint32_t> widths;
  bool quiet = false;
  std::string rerun_command;
  int threads = 1;  // this process's worker threads
  // This run's counts, for the progress and summary lines.
  size_t before = 0, computed = 0, rows = 0;
  double busy = 0, cpu = 0;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double last_line = -1;  // when the last "chunk committed" line was printed (seconds since start)
};

namespace {
fs::path chunk_dir(const ShardOptions& o, const std::string& output) {
  return o.chunks_dir.empty() ? fs::path(output + ".chunks") : fs::path(o.chunks_dir);
}
} // namespace

ShardedRows::ShardedRows(const Worker& worker, const MpiSession& mpi, const ShardOptions& options,
                         const std::string& output, const std::string& manifest, const std::vector<uint64_t>& set_rows,
                         std::vector<uint32_t> set_widths, bool quiet)
    : s_(new State{worker, &mpi,
                   bake::ChunkStore(chunk_dir(options, output), manifest, bake::row_chunks(set_rows, options.chunk_rows)),
                   std::move(set_widths), quiet, options.rerun_command,
                   int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism))}) {
  PRT_CHECK_OP(s_->widths.size(), ==, set_rows.size());
}

ShardedRows::~ShardedRows() = default;

bool ShardedRows::run(const std::function<void()>& body) {
  State& s = *s_;
  const Worker& w = s.worker;
  std::exception_ptr error;
  try {
    if (w.computes) {
      s.before = s.store.committed_count();
      s.mpi->all(true);  // every rank counted before any commits
      if (!s.quiet && w.index == 0)
        std::printf("chunks: %zu in %s; %zu committed before this run (reused), %zu to compute by %d worker(s), %s "
                    "claiming\n",
                    s.store.chunks().size(), s.store.dir().string().c_str(), s.before, s.store.chunks().size() - s.before,
                    w.count, w.claim == Claim::Static ? "static" : "dynamic");
      std::fflush(stdout);
      s.start = std::chrono::steady_clock::now();
      body();
    }
    if (w.computes && !s.quiet)
      std::printf("worker %d/%d (%s): computed %zu chunks (%zu rows), busy %.2f s (%.2f CPU s)\n", w.index, w.count,
                  w.launcher.c_str(), s.computed, s.rows, s.busy, s.cpu);
    std::fflush(stdout);
  } catch (...) {
    error = std::current_exception();
  }
  const bool every = s.mpi->all(!error);  // under mpirun: the barrier before rank 0 merges
  if (error) std::rethrow_exception(error);
  if (!every && w.merges)
    throw bake::InputError(s.store.dir().string(), "another worker failed (its message is above); nothing merged");
  return w.merges;
}

void ShardedRows::work(const Compute& compute, std::optional<uint32_t> set, const LastSet& last_set) {
  State& s = *s_;
  const Worker& w = s.worker;
  if (!w.computes) return;
  const auto& chunks = s.store.chunks();
  const bool say = !s.quiet && w.index == 0;
  const bake::Monitor cancel{{}, &interrupt_token()};
  std::optional<uint32_t> last;
  for (size_t i = 0; i < chunks.size(); ++i) {
    if (set && chunks[i].set != *set) continue;
    if (last_set && !last) last = last_set();
    if (last && chunks[i].set > *last) break;  // chunks run set after set
    if (w.claim == Claim::Static && int(i % size_t(w.count)) != w.index) continue;
    if (s.store.committed(i)) {
      // A foreign or corrupt chunk is refused now, before hours of work (static: this worker's
      // own; dynamic: the first worker checks them all).
      if (w.claim == Claim::Static || w.index == 0) s.store.read(i, s.widths.at(chunks[i].set));
      continue;
    }
    if (w.claim == Claim::Dynamic && !s.store.claim(i, w.run_id)) continue;
    bake::ChunkData d = compute(chunks[i], cancel);
    d.range = chunks[i];
    d.width = s.widths.at(chunks[i].set);
    s.store.commit(i, d);
    ++s.computed, s.rows += chunks[i].rows(), s.busy += d.seconds, s.cpu += d.cpu_seconds;
    if (say) {
      // Every worker's committed chunks (the files), against all chunks the bake may need: the
      // progress and ETA of the whole bake. Until the last set is known (FIV shells), the total
      // counts every set, and the ETA is an upper bound.
      size_t now = 0, total = 0;
      for (size_t c = 0; c < chunks.size(); ++c)
        if (!last || chunks[c].set <= *last) {
          ++total;
          now += s.store.committed(c) ? 1 : 0;
        }
      const size_t before = std::min(s.before, now);
      const double elapsed = seconds_since(s.start);
      // In a log (stdout not a terminal) a few lines, as the progress lines: the first, then at
      // most one every 10 s, and the last.
      if (!isatty(STDOUT_FILENO) && s.last_line >= 0 && now < total &&
          elapsed - s.last_line < ProgressBar::kLineSpacingSeconds)
        continue;
      s.last_line = elapsed;
      const double eta = now > before ? elapsed * double(total - now) / double(now - before) : 0.0;
      std::printf("chunk %zu committed: %zu/%zu chunks of all workers, %.1f s, ETA %s%.0f s\n", i, now, total, elapsed,
                  last_set && !last ? "at most " : "", eta);
      std::fflush(stdout);
    }
  }
}

bool ShardedRows::complete(uint32_t set) const {
  const auto& chunks = s_->store.chunks();
  for (size_t i = 0; i < chunks.size(); ++i)
    if (chunks[i].set == set && !s_->store.committed(i)) return false;
  return true;
}

bake::ChunkData ShardedRows::join(uint32_t set) const {
  bake::ChunkData out;
  join(set, out);
  return out;
}

void ShardedRows::join(uint32_t set, bake::ChunkData& out) const {
  const State& s = *s_;
  const auto& chunks = s.store.chunks();
  const uint32_t W = s.widths.at(set);
  out.width = W;
  out.range = {set, 0, 0};
  for (const bake::ChunkRange& c : chunks)
    if (c.set == set) out.range.end = std::max(out.range.end, c.end);
  out.values.resize(out.range.end * W);  // every row is read into place below
  out.std_error.clear();
  out.closed_form = 0;
  out.seconds = out.cpu_seconds = 0;
  for (size_t i = 0; i < chunks.size(); ++i)
    if (chunks[i].set == set && !s.store.read_into(i, W, out))
      throw bake::InputError(s.store.chunk_path(i).string(),
                             "missing chunk " + std::to_string(i) + " (rows " + std::to_string(chunks[i].begin) + "-" +
                                 std::to_string(chunks[i].end) + "): no worker committed it; rerun the bake to compute it");
}

bake::VertexBake ShardedRows::merge(uint32_t set, const bake::ProductLayout& layout) const {
  PRT_CHECK_OP(s_->widths.at(set), ==, layout.width);
  bake::ChunkData d = join(set);
  bake::VertexBake out;
  out.layout = layout;
  out.values = std::move(d.values);
  out.std_error = std::move(d.std_error);
  out.std_error.resize(out.values.size());  // a vertex bake's chunks all hold them
  out.seconds = d.seconds;
  out.cpu_seconds = d.cpu_seconds;
  if (const int t = threads_of_chunks(); t > 0) out.threads = t;
  out.closed_form = d.closed_form;
  return out;
}

void ShardedRows::finish() const { s_->store.remove(); }

std::optional<std::string> ShardedRows::kept_after_cancel() const {
  const State& s = *s_;
  const size_t committed = s.store.committed_count(), total = s.store.chunks().size();
  if (committed == 0) {
    s.store.remove();  // claims and temporaries of this run, and the directory it created
    return std::nullopt;
  }
  const Worker& w = s.worker;
  std::string line = std::to_string(committed) + " of " + std::to_string(total) + " chunks are committed (" +
                     std::to_string(s.computed) + " by this run) and kept in " + s.store.dir().string() + "/; ";
  if (!w.computes)
    line += "the merge wrote nothing; to merge, rerun: ";
  else if (s.mpi->active())
    line += "to resume, rerun the same mpirun command (each rank ran: ";
  else if (!w.merges)
    line += "to resume this worker's share, rerun: ";
  else
    line += "to resume, rerun: ";
  line += s.rerun_command;
  if (w.computes && s.mpi->active()) line += ")";
  else if (w.computes && !w.merges) line += " (then --merge)";
  return line;
}

int ShardedRows::threads_of_chunks() const {
  const State& s = *s_;
  return s.worker.computes && s.worker.count == 1 && s.before == 0 ? s.threads : 0;
}

} // namespace prt::tool
