// chunks.cpp — chunk files of sharded bakes (bake/core/chunks.h): layout, atomic commit, verification,
// claims.
#include <bake/core/chunks.h>
#include <bake/core/error.h>
#include <bake/core/sha256.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace prt::bake {
namespace {

// File layout: kMagic, manifest (64 hex), index u64, set u32, begin u64, end u64, width u32,
// columns u32 (1: values, 2: values and std_error), closed_form u64, cpu_seconds f64, seconds f64,
// values f64[rows·width], std_error f64[rows·width] (when 2 columns), then the SHA-256 (64 hex) of
// every byte before it.
constexpr char kMagic[8] = {'P', 'R', 'T', 'C', 'H', 'N', 'K', '2'};
constexpr size_t kDigest = 64;
constexpr size_t kHeader = sizeof kMagic + kDigest + 8 + 4 + 8 + 8 + 4 + 4 + 8 + 8 + 8;

template <class T>
void put(std::string& out, const T& x) {
  out.append(reinterpret_cast<const char*>(&x), sizeof x);
}
template <class T>
T get(const char* in, size_t& at) {
  T x;
  std::memcpy(&x, in + at, sizeof x);
  at += sizeof x;
  return x;
}

std::string digest_of(const std::string& bytes, size_t n) {
  return sha256_bytes(std::span(reinterpret_cast<const std::byte*>(bytes.data()), n));
}

std::string errno_text() { return std::strerror(errno); }

// Writes all of `bytes` to `fd`; false on a failed write.
bool write_all(int fd, const std::string& bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += size_t(n);
  }
  return true;
}

// Reads exactly `n` bytes from `fd` into `to`; false on a failed or short read.
bool read_all(int fd, void* to, size_t n) {
  size_t done = 0;
  while (done < n) {
    const ssize_t got = ::read(fd, static_cast<char*>(to) + done, n - done);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    done += size_t(got);
  }
  return true;
}

// Closes a file descriptor at the end of its scope.
struct Fd {
  int fd;
  ~Fd() { ::close(fd); }
};

std::string host_name() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0) return "host";
  return buf;
}

} // namespace

std::vector<ChunkRange> row_chunks(std::span<const uint64_t> set_rows, uint64_t rows_per_chunk) {
  PRT_CHECK(rows_per_chunk > 0);
  std::vector<ChunkRange> out;
  for (size_t s = 0; s < set_rows.size(); ++s)
    for (uint64_t b = 0; b < set_rows[s]; b += rows_per_chunk)
      out.push_back({uint32_t(s), b, std::min(set_rows[s], b + rows_per_chunk)});
  return out;
}

ChunkStore::ChunkStore(fs::path dir, std::string manifest, std::vector<ChunkRange> chunks)
    : dir_(std::move(dir)), manifest_(std::move(manifest)), chunks_(std::move(chunks)) {
  PRT_CHECK_OP(manifest_.size(), ==, kDigest);
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (!fs::is_directory(dir_)) throw InputError(dir_.string(), "cannot create the chunk directory: " + ec.message());
}

fs::path ChunkStore::chunk_path(size_t index) const {
  char name[32];
  std::snprintf(name, sizeof name, "c%06zu.chunk", index);
  return dir_ / name;
}

bool ChunkStore::committed(size_t index) const {
  std::error_code ec;
  return fs::is_regular_file(chunk_path(index), ec);
}

size_t ChunkStore::committed_count() const {
  size_t n = 0;
  for (size_t i = 0; i < chunks_.size(); ++i) n += committed(i) ? 1 : 0;
  return n;
}

void ChunkStore::commit(size_t index, const ChunkData& d) const {
  PRT_CHECK(index < chunks_.size() && d.range == chunks_[index]);
  PRT_CHECK_OP(d.values.size(), ==, d.range.rows() * d.width);
  PRT_CHECK(d.std_error.empty() || d.std_error.size() == d.values.size());
  const uint32_t columns = d.std_error.empty() ? 1 : 2;
  std::string bytes;
  bytes.reserve(kHeader + 8 * columns * d.values.size() + kDigest);
  bytes.append(kMagic, sizeof kMagic);
  bytes += manifest_;
  put(bytes, uint64_t(index));
  put(bytes, d.range.set);
  put(bytes, d.range.begin);
  put(bytes, d.range.end);
  put(bytes, d.width);
  put(bytes, columns);
  put(bytes, d.closed_form);
  put(bytes, d.cpu_seconds);
  put(bytes, d.seconds);
  for (const auto* column : {&d.values, &d.std_error})
    bytes.append(reinterpret_cast<const char*>(column->data()), column->size() * sizeof(double));
  bytes += digest_of(bytes, bytes.size());

  const fs::path final_path = chunk_path(index);
  const fs::path temp = final_path.string() + ".tmp." + host_name() + "." + std::to_string(getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw SystemError(temp.string() + ": cannot create: " + errno_text());
  const bool ok = write_all(fd, bytes) && ::fsync(fd) == 0;
  const std::string why = errno_text();
  ::close(fd);
  if (!ok || ::rename(temp.c_str(), final_path.c_str()) != 0) {
    const std::string problem = ok ? errno_text() : why;
    ::unlink(temp.c_str());
    throw SystemError(final_path.string() + ": cannot commit the chunk: " + problem);
  }
  // The rename itself is durable once the directory is.
  const int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

std::optional<ChunkData> ChunkStore::read(size_t index, uint32_t width) const {
  PRT_CHECK(index < chunks_.size());
  ChunkData d;
  d.range = chunks_[index];
  d.width = width;
  d.values.resize(size_t(d.range.rows()) * width);
  if (!read_into(index, width, d)) return std::nullopt;
  return d;
}

bool ChunkStore::read_into(size_t index, uint32_t width, ChunkData& out) const {
  PRT_CHECK(index < chunks_.size());
  const ChunkRange& want = chunks_[index];
  const size_t n = size_t(want.rows()) * width;  // values in each column
  PRT_CHECK(out.range.begin <= want.begin && size_t(want.end - out.range.begin) * width <= out.values.size());
  const fs::path path = chunk_path(index);
  const std::string file = path.string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) return false;
    throw InputError(file, "cannot read the chunk file: " + errno_text());
  }
  const Fd closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw InputError(file, "cannot read the chunk file: " + errno_text());
  const size_t size = size_t(std::max<off_t>(st.st_size, 0));
  char header[kHeader];
  if (size < kHeader + kDigest || !read_all(fd, header, kHeader) || std::memcmp(header, kMagic, sizeof kMagic) != 0)
    throw InputError(file, "not a chunk file (truncated or wrong format); remove it and rerun the bake to recompute it");
  size_t at = sizeof kMagic + kDigest;
  const uint64_t stored_index = get<uint64_t>(header, at);
  ChunkRange range;
  range.set = get<uint32_t>(header, at);
  range.begin = get<uint64_t>(header, at);
  range.end = get<uint64_t>(header, at);
  const uint32_t stored_width = get<uint32_t>(header, at);
  const uint32_t columns = get<uint32_t>(header, at);
  const uint64_t closed_form = get<uint64_t>(header, at);
  const double cpu_seconds = get<double>(header, at), seconds = get<double>(header, at);
  const bool same_chunk = stored_index == index && range == want && stored_width == width;
  const size_t body = size - kDigest;
  const bool fits = same_chunk && (columns == 1 || columns == 2) && body == kHeader + columns * n * sizeof(double);

  // The digest covers every byte before it: the header, then the rows, read into their place
  // when the header says where that is, else only hashed (a damaged header reads as corrupt).
  Sha256 hash;
  hash.update(std::as_bytes(std::span(header)));
  bool complete = true;
  if (fits) {
    const size_t offset = size_t(want.begin - out.range.begin) * width;
    if (columns == 2 && out.std_error.size() < out.values.size()) out.std_error.resize(out.values.size());
    for (std::vector<double>* column : {&out.values, &out.std_error}) {
      if (column == &out.std_error && columns == 1) break;
      const std::span<double> rows(column->data() + offset, n);
      complete = complete && read_all(fd, rows.data(), rows.size_bytes());
      hash.update(std::as_bytes(rows));
    }
  } else {
    std::vector<char> buffer(std::min<size_t>(body - kHeader, size_t(1) << 16));
    for (size_t left = body - kHeader; left > 0 && complete;) {
      const size_t piece = std::min(left, buffer.size());
      complete = read_all(fd, buffer.data(), piece);
      hash.update(std::as_bytes(std::span(buffer.data(), piece)));
      left -= piece;
    }
  }
  char digest[kDigest];
  if (!complete || !read_all(fd, digest, kDigest)) throw InputError(file, "cannot read the chunk file");
  if (hash.hex_digest() != std::string_view(digest, kDigest))
    throw InputError(file, "corrupt chunk: its SHA-256 does not match its contents; remove it and rerun the bake to "
                           "recompute it");
  const std::string_view stored_manifest(header + sizeof kMagic, kDigest);
  if (stored_manifest != manifest_)
    throw InputError(file, "chunk of another bake (other inputs, options, integrator, seed or chunk layout: manifest " +
                               std::string(stored_manifest.substr(0, 12)) + "... is not this bake's " +
                               manifest_.substr(0, 12) + "...); remove the chunk directory or rerun with the same "
                               "inputs and options");
  if (!same_chunk)
    throw InputError(file, "chunk " + std::to_string(stored_index) + " of set " + std::to_string(range.set) + ", rows " +
                               std::to_string(range.begin) + "-" + std::to_string(range.end) + ", width " +
                               std::to_string(stored_width) + " is not this bake's chunk " + std::to_string(index) +
                               " (set " + std::to_string(want.set) + ", rows " + std::to_string(want.begin) + "-" +
                               std::to_string(want.end) + ", width " + std::to_string(width) + ")");
  if (!fits)
    throw InputError(file, "chunk holds " + std::to_string(body) + " bytes in " + std::to_string(columns) +
                               " column(s) where its rows need " + std::to_string(kHeader + 2 * n * sizeof(double)) +
                               " in 2 or " + std::to_string(kHeader + n * sizeof(double)) + " in 1");
  out.closed_form += closed_form;
  out.cpu_seconds += cpu_seconds;
  out.seconds += seconds;
  return true;
}

bool valid_run_id(std::string_view id) {
  return !id.empty() && id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.") ==
                            std::string_view::npos;
}

bool ChunkStore::claim(size_t index, const std::string& run_id) const {
  PRT_CHECK(valid_run_id(run_id));
  const fs::path path = chunk_path(index).string() + ".claim." + run_id;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    if (errno == EEXIST) return false;
    throw SystemError(path.string() + ": cannot create the claim: " + errno_text());
  }
  write_all(fd, host_name() + " " + std::to_string(getpid()) + "\n");
  ::close(fd);
  return true;
}

void ChunkStore::remove() const {
  std::error_code ec;
  for (size_t i = 0; i < chunks_.size(); ++i) fs::remove(chunk_path(i), ec);
  // Claims and temporaries: "<chunk>.claim.*", "<chunk>.tmp.*" of this store's chunk names.
  for (const auto& entry : fs::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 13 && name[0] == 'c' && name.compare(7, 6, ".chunk") == 0 &&
        (name.find(".chunk.claim.") == 7 || name.find(".chunk.tmp.") == 7))
      fs::remove(entry.path(), ec);
  }
  fs::remove(dir_, ec);  // only if empty
}

} // namespace prt::bake
