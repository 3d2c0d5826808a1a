// writer.cpp — write_file: validate, write "<name>.tmp.<host>.<pid>" deterministically, rename;
// remove this machine's stale temporaries of dead bakes to the same name first.
#include <formats/names.h>
#include <formats/prtfile.h>

#include <formats/temporaries.h>
#include <formats/testing.h>

#include "chunk_filters.h"
#include "h5util.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <memory>
#include <string>
#include <set>
#include <system_error>

namespace prt::formats {
namespace {

using detail::Hid;

constexpr uint64_t kChunkBytes = 64 * 1024;
constexpr unsigned kDeflateLevel = 6;  // recorded in the deflate filter's parameters; libdeflate's scale
// Chunks encoded at once (in parallel) before they are written in order: bounds the memory held.
constexpr std::size_t kChunkBatch = 256;
// Direct chunk writes store the array's memory bytes as the file's: both little-endian.
static_assert(std::endian::native == std::endian::little, "the writer stores native bytes as little-endian");

// Who filters the chunks: we do (chunk_filters.h; parallel, libdeflate) or, for the tests' reference
// writer, HDF5's own pipeline (H5Dwrite, zlib).
enum class Filters { ours, library };

// One chunk of a dataset: its first element (HDF5's chunk offset) and the flat range of the
// row-major array it holds. The writer's chunk shapes make every chunk one contiguous range: all
// dimensions after `split` whole, the ones before it 1 (Writer::write_dataset).
struct ChunkSpan {
  std::vector<hsize_t> offset;
  uint64_t first = 0, count = 0;
};

std::vector<ChunkSpan> chunk_spans(const std::vector<hsize_t>& dims, const std::vector<hsize_t>& chunk) {
  const int rank = int(dims.size());
  int split = rank - 1;  // the last dimension not taken whole (-1: the chunk is the whole array)
  while (split >= 0 && chunk[size_t(split)] == dims[size_t(split)]) --split;
  uint64_t inner = 1;
  for (int k = split + 1; k < rank; ++k) inner *= dims[size_t(k)];
  uint64_t outer = 1;
  for (int k = 0; k < split; ++k) {
    if (chunk[size_t(k)] != 1) throw FormatError("", "internal error: a chunk shape that is not one contiguous range");
    outer *= dims[size_t(k)];
  }
  std::vector<ChunkSpan> out;
  if (split < 0) {
    out.push_back({std::vector<hsize_t>(dims.size(), 0), 0, inner});
    return out;
  }
  const hsize_t along = dims[size_t(split)], step = chunk[size_t(split)];
  for (uint64_t o = 0; o < outer; ++o)
    for (hsize_t a = 0; a < along; a += step) {
      ChunkSpan c{std::vector<hsize_t>(dims.size(), 0), (o * along + a) * inner, std::min(step, along - a) * inner};
      uint64_t rest = o;  // o unravelled over the dimensions before `split`
      for (int k = split - 1; k >= 0; --k) {
        c.offset[size_t(k)] = rest % dims[size_t(k)];
        rest /= dims[size_t(k)];
      }
      c.offset[size_t(split)] = a;
      out.push_back(std::move(c));
    }
  return out;
}

class Writer {
public:
  Writer(std::string file_for_messages, hid_t file, bool checksum_data, Filters filters)
      : msg_file_(std::move(file_for_messages)), file_(file), checksum_data_(checksum_data), filters_(filters) {}

  [[noreturn]] void fail(const std::string& what) const {
    const std::string detail = detail::take_hdf5_error();
    throw FormatError(msg_file_, what + (detail.empty() ? "" : " (HDF5: " + detail + ")"));
  }

  void check(herr_t status, const std::string& what) const {
    if (status < 0) fail(what);
  }
  Hid check(Hid id, const std::string& what) const {
    if (!id.valid()) fail(what);
    return id;
  }

  // Creation property list shared by groups: no time stamps (determinism).
  Hid group_plist() const {
    Hid gcpl = check(detail::plist_id(H5Pcreate(H5P_GROUP_CREATE)), "cannot create group properties");
    check(H5Pset_obj_track_times(gcpl.get(), false), "cannot disable group time tracking");
    return gcpl;
  }

  // Creates `group` and its missing ancestors, each once, in the order first needed.
  void ensure_group(const std::string& group) {
    if (group.empty() || group == "/" || created_.count(group)) return;
    ensure_group(group.substr(0, std::max<std::size_t>(group.rfind('/'), 1)));
    Hid gcpl = group_plist();
    Hid g = check(detail::group_id(H5Gcreate2(file_, group.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT)),
                  "cannot create group '" + group + "'");
    created_.insert(group);
  }

  void write_attr(hid_t owner, const Attr& a, const std::string& owner_name) const {
    const std::string what = "cannot write attribute '" + a.name + "' of " + owner_name;
    if (const auto* s = std::get_if<std::string>(&a.value)) {
      Hid type = check(detail::make_utf8_string_type(s->size()), what);
      Hid space = check(detail::space_id(H5Screate(H5S_SCALAR)), what);
      Hid attr = check(detail::attr_id(H5Acreate2(owner, a.name.c_str(), type.get(), space.get(),
                                                 H5P_DEFAULT, H5P_DEFAULT)), what);
      std::string padded = *s;
      padded.resize(std::max<std::size_t>(s->size(), 1), '\0');
      check(H5Awrite(attr.get(), type.get(), padded.data()), what);
      return;
    }
    if (const auto* vs = std::get_if<std::vector<std::string>>(&a.value)) {
      // One fixed length for the array, its longest string's; an empty array has a null dataspace.
      std::size_t width = 1;
      for (const std::string& s : *vs) width = std::max(width, s.size());
      std::string packed(width * vs->size(), '\0');
      for (std::size_t i = 0; i < vs->size(); ++i) packed.replace(i * width, (*vs)[i].size(), (*vs)[i]);
      const hsize_t n = vs->size();
      Hid type = check(detail::make_utf8_string_type(width), what);
      Hid space = check(detail::space_id(n == 0 ? H5Screate(H5S_NULL) : H5Screate_simple(1, &n, nullptr)), what);
      Hid attr = check(detail::attr_id(H5Acreate2(owner, a.name.c_str(), type.get(), space.get(),
                                                 H5P_DEFAULT, H5P_DEFAULT)), what);
      if (n > 0) check(H5Awrite(attr.get(), type.get(), packed.data()), what);
      return;
    }
    hid_t file_type = H5T_STD_I64LE, mem_type = H5T_NATIVE_INT64;
    const void* buf = nullptr;
    hsize_t n = 0;
    bool scalar = false;
    if (const auto* i = std::get_if<int64_t>(&a.value)) {
      buf = i, scalar = true;
    } else if (const auto* d = std::get_if<double>(&a.value)) {
      buf = d, scalar = true, file_type = H5T_IEEE_F64LE, mem_type = H5T_NATIVE_DOUBLE;
    } else if (const auto* vd = std::get_if<std::vector<double>>(&a.value)) {
      buf = vd->data(), n = vd->size(), file_type = H5T_IEEE_F64LE, mem_type = H5T_NATIVE_DOUBLE;
    } else {
      const auto& vi = std::get<std::vector<int64_t>>(a.value);
      buf = vi.data(), n = vi.size();
    }
    // An empty vector is stored with a null dataspace (no elements) of the right type.
    Hid space = check(detail::space_id(scalar ? H5Screate(H5S_SCALAR)
                                       : n == 0 ? H5Screate(H5S_NULL)
                                                : H5Screate_simple(1, &n, nullptr)),
                      what);
    Hid attr = check(detail::attr_id(H5Acreate2(owner, a.name.c_str(), file_type, space.get(),
                                               H5P_DEFAULT, H5P_DEFAULT)), what);
    if (scalar || n > 0) check(H5Awrite(attr.get(), mem_type, buf), what);
  }

  void write_dataset(const Dataset& d) {
    const std::string name = "dataset '" + d.path + "'";
    ensure_group(d.path.substr(0, std::max<std::size_t>(d.path.rfind('/'), 1)));

    const int rank = static_cast<int>(d.shape.size());
    std::vector<hsize_t> dims(d.shape.begin(), d.shape.end());
    Hid space = check(detail::space_id(H5Screate_simple(rank, dims.data(), nullptr)),
                      "cannot create the dataspace of " + name);

    hid_t file_type = H5T_IEEE_F32LE, mem_type = H5T_NATIVE_FLOAT;
    std::size_t elem = 4;
    const void* buf = nullptr;
    std::visit([&](const auto& v) { buf = v.data(); }, d.data);
    if (d.data.index() == 1) file_type = H5T_STD_U32LE, mem_type = H5T_NATIVE_UINT32;
    if (d.data.index() == 2) file_type = H5T_STD_U8LE, mem_type = H5T_NATIVE_UINT8, elem = 1;
    if (d.data.index() == 3) file_type = H5T_IEEE_F64LE, mem_type = H5T_NATIVE_DOUBLE, elem = 8;
    Hid half;
    if (d.data.index() == 4) {  // float16 (v8): the bits as they are, in the same type in memory and on disk
      half = check(detail::make_float16_type(), "cannot make the float16 type of " + name);
      file_type = mem_type = half.get(), elem = 2;
    }

    Hid dcpl = check(detail::plist_id(H5Pcreate(H5P_DATASET_CREATE)), "cannot create properties of " + name);
    check(H5Pset_obj_track_times(dcpl.get(), false), "cannot disable time tracking of " + name);
    const bool empty = std::find(dims.begin(), dims.end(), hsize_t{0}) != dims.end();
    std::vector<hsize_t> chunk(dims.size(), 1);
    if (!empty) {
      // Chunks of ~kChunkBytes: whole trailing dimensions while they fit, then a run of the
      // first dimension that does not fit (for [V, ...] that is a block of vertices); the ones
      // before it are 1, so that a chunk is one contiguous range of the array (chunk_spans).
      uint64_t inner = elem;
      for (int k = rank - 1; k >= 0; --k) {
        if (inner * dims[k] <= kChunkBytes) {
          chunk[k] = dims[k];
          inner *= dims[k];
        } else {
          chunk[k] = std::clamp<hsize_t>(kChunkBytes / inner, 1, dims[k]);
          break;
        }
      }
      check(H5Pset_chunk(dcpl.get(), rank, chunk.data()), "cannot set chunking of " + name);
      check(H5Pset_shuffle(dcpl.get()), "cannot set the shuffle filter of " + name);
      check(H5Pset_deflate(dcpl.get(), kDeflateLevel), "cannot set deflate compression of " + name);
      if (checksum_data_) check(H5Pset_fletcher32(dcpl.get()), "cannot set the fletcher32 checksum of " + name);
    }
    Hid ds = check(detail::dataset_id(H5Dcreate2(file_, d.path.c_str(), file_type, space.get(),
                                                H5P_DEFAULT, dcpl.get(), H5P_DEFAULT)),
                   "cannot create " + name);
    if (!empty && filters_ == Filters::library)
      check(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf), "cannot write " + name);
    else if (!empty)
      write_chunks(ds.get(), dims, chunk, elem, static_cast<const std::byte*>(buf), name);
    for (const Attr& a : d.attrs) write_attr(ds.get(), a, name);
    check(ds.close(), "cannot close " + name);
  }

  void write_group_attrs(const std::string& group, const std::vector<Attr>& attrs) {
    ensure_group(group);
    Hid g = check(detail::group_id(H5Gopen2(file_, group.c_str(), H5P_DEFAULT)),
                  "cannot open group '" + group + "'");
    for (const Attr& a : attrs) write_attr(g.get(), a, "group '" + group + "'");
  }

private:
  // The chunks of one dataset, filtered here in parallel (chunk_filters.h) a batch at a time and
  // written whole, in row-major chunk order: the same bytes whatever the thread count. Chunks
  // past the array's end are padded with zeros, HDF5's default fill value, as H5Dwrite pads them.
  void write_chunks(hid_t ds, const std::vector<hsize_t>& dims, const std::vector<hsize_t>& chunk, std::size_t elem,
                    const std::byte* bytes, const std::string& name) const {
    try {
      write_chunks_of(ds, dims, chunk, elem, bytes, name);
    } catch (const FormatError& e) {  // the encoder's errors do not know the file or the dataset
      if (!e.file().empty()) throw;
      fail("cannot write " + name + ": " + e.defect());
    }
  }

  void write_chunks_of(hid_t ds, const std::vector<hsize_t>& dims, const std::vector<hsize_t>& chunk,
                       std::size_t elem, const std::byte* bytes, const std::string& name) const {
    const std::vector<ChunkSpan> spans = chunk_spans(dims, chunk);
    uint64_t chunk_elements = 1;
    for (const hsize_t c : chunk) chunk_elements *= c;
    tbb::enumerable_thread_specific<std::unique_ptr<detail::ChunkEncoder>> encoders;
    std::vector<std::vector<std::byte>> encoded(std::min(kChunkBatch, spans.size()));
    for (std::size_t b = 0; b < spans.size(); b += kChunkBatch) {
      const std::size_t n = std::min(kChunkBatch, spans.size() - b);
      // Isolated: a thread waiting here must not pick up outer work that may take the HDF5 lock.
      tbb::this_task_arena::isolate([&] {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
          std::unique_ptr<detail::ChunkEncoder>& encoder = encoders.local();
          if (!encoder) encoder = std::make_unique<detail::ChunkEncoder>(int(kDeflateLevel), checksum_data_);
          std::vector<std::byte> padded;
          for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const ChunkSpan& c = spans[b + i];
            std::span<const std::byte> whole(bytes + c.first * elem, c.count * elem);
            if (c.count != chunk_elements) {
              padded.assign(chunk_elements * elem, std::byte{0});
              std::memcpy(padded.data(), whole.data(), whole.size());
              whole = padded;
            }
            encoded[i] = encoder->encode(whole, elem);
          }
        });
      });
      for (std::size_t i = 0; i < n; ++i)
        check(H5Dwrite_chunk(ds, H5P_DEFAULT, 0, spans[b + i].offset.data(), encoded[i].size(), encoded[i].data()),
              "cannot write " + name);
    }
  }

  std::string msg_file_;
  hid_t file_;
  bool checksum_data_;
  Filters filters_;
  std::set<std::string> created_;
};

// Removes the temporary file unless dismissed (after the successful rename).
struct TempGuard {
  std::filesystem::path path;
  bool armed = true;
  ~TempGuard() {
    if (armed) {
      std::error_code ec;
      std::filesystem::remove(path, ec);
    }
  }
};

// The on-disk format: ours (HDF5 1.10 structures, every metadata block checksummed, fletcher32 on
// data), or, for reader tests only, HDF5's oldest (superblock 0, version-1 object headers,
// symbol-table groups, version-1 B-tree chunk indexes: no checksum anywhere) — with its own
// superblock (version 0) or under a checksummed version-2 one (a non-default file-space setting
// makes HDF5 write that; the objects below it stay unchecksummed).
enum class OnDisk { current, oldest, oldest_objects };

void write_checked(const std::filesystem::path& final_path, const File& file, bool add_format,
                   OnDisk on_disk = OnDisk::current, Filters filters = Filters::ours) {
  const std::string msg_file = final_path.string();

  if (final_path.filename().empty())
    throw FormatError(msg_file, "the output path names a directory, not a file");
  std::filesystem::path dir = final_path.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw FormatError(msg_file, "output directory '" + dir.string() + "' does not exist");
  if (std::filesystem::is_directory(final_path, ec))
    throw FormatError(msg_file, "the output path is an existing directory");

  const std::string prefix = final_path.filename().string() + ".tmp." + host_tag() + ".";
  const std::filesystem::path tmp = dir / temporary_name(prefix);
  remove_stale_temporaries(dir, prefix);

  const std::lock_guard lock(detail::hdf5_mutex());
  detail::silence_hdf5_errors();
  TempGuard guard{tmp};
  {
    auto fail = [&](const std::string& what) -> void {
      const std::string d = detail::take_hdf5_error();
      throw FormatError(msg_file, what + (d.empty() ? "" : " (HDF5: " + d + ")"));
    };
    Hid fcpl = detail::plist_id(H5Pcreate(H5P_FILE_CREATE));
    Hid fapl = detail::plist_id(H5Pcreate(H5P_FILE_ACCESS));
    if (!fcpl.valid() || !fapl.valid()) fail("cannot create HDF5 file properties");
    // The root group is created with the file: no time stamps there either.
    if (H5Pset_obj_track_times(fcpl.get(), false) < 0 ||
        (on_disk == OnDisk::oldest_objects &&
         H5Pset_file_space_strategy(fcpl.get(), H5F_FSPACE_STRATEGY_FSM_AGGR, 1, 1) < 0) ||
        (on_disk == OnDisk::current && H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_V110) < 0) ||
        H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG) < 0)
      fail("cannot set HDF5 file properties");
    Hid f = detail::file_id(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()));
    if (!f.valid())
      fail("cannot create temporary file '" + tmp.string() + "' (is '" + dir.string() +
           "' writable?)");

    Writer w(msg_file, f.get(), on_disk == OnDisk::current, filters);
    Hid root = detail::group_id(H5Gopen2(f.get(), "/", H5P_DEFAULT));
    if (!root.valid()) fail("cannot open the root group");
    if (add_format) {
      w.write_attr(root.get(), {std::string(names::kFormat), std::string(kFormatName)}, "the root group");
      w.write_attr(root.get(), {std::string(names::kFormatVersion), written_format_version(file)}, "the root group");
    }
    for (const Attr& a : file.root_attrs)
      if (!add_format || (a.name != names::kFormat && a.name != names::kFormatVersion))  // validated equal
        w.write_attr(root.get(), a, "the root group");
    root.close();
    for (const Dataset& d : file.datasets) w.write_dataset(d);
    for (const auto& [group, attrs] : file.group_attrs) w.write_group_attrs(group, attrs);
    if (f.close() < 0) fail("cannot finish writing temporary file '" + tmp.string() + "'");
  }
  std::filesystem::rename(tmp, final_path, ec);
  if (ec)
    throw FormatError(msg_file, "cannot rename '" + tmp.string() + "' onto it: " + ec.message());
  guard.armed = false;
}

} // namespace

void write_file(const std::filesystem::path& final_path, const File& file) {
  validate(file, final_path);
  write_checked(final_path, file, true);
}

namespace testing {
namespace {
void require_memory_safe(const std::filesystem::path& final_path, const File& file) {
  for (const Dataset& d : file.datasets)
    if (d.shape.empty() || d.shape.size() > 32 || d.path.empty() || d.path[0] != '/' ||
        shape_product(d.shape) != element_count(d.data))
      throw FormatError(final_path.string(), "dataset '" + d.path + "' is malformed (rank or size)");
}
} // namespace

void write_file_unvalidated(const std::filesystem::path& final_path, const File& file) {
  require_memory_safe(final_path, file);
  write_checked(final_path, file, false);
}

void write_file_oldest_format(const std::filesystem::path& final_path, const File& file, OldestFormat which) {
  require_memory_safe(final_path, file);
  write_checked(final_path, file, false,
                which == OldestFormat::everywhere ? OnDisk::oldest : OnDisk::oldest_objects);
}

void write_file_library_filters(const std::filesystem::path& final_path, const File& file) {
  require_memory_safe(final_path, file);
  write_checked(final_path, file, false, OnDisk::current, Filters::library);
}
} // namespace testing

} // namespace prt::formats
