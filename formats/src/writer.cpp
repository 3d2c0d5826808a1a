// writer.cpp — write_file: validate, write "<name>.tmp.<host>.<pid>" deterministically, rename;
// remove this machine's stale temporaries of dead bakes to the same name first.
#include <formats/names.h>
#include <formats/prtfile.h>

#include <formats/testing.h>

#include "h5util.h"
#include "temporaries.h"


#include <algorithm>
#include <string>
#include <set>
#include <system_error>

namespace prt::formats {
namespace {

using detail::Hid;

constexpr uint64_t kChunkBytes = 64 * 1024;
constexpr unsigned kDeflateLevel = 6;

class Writer {
public:
  Writer(std::string file_for_messages, hid_t file, bool checksum_data)
      : msg_file_(std::move(file_for_messages)), file_(file), checksum_data_(checksum_data) {}

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

    Hid dcpl = check(detail::plist_id(H5Pcreate(H5P_DATASET_CREATE)), "cannot create properties of " + name);
    check(H5Pset_obj_track_times(dcpl.get(), false), "cannot disable time tracking of " + name);
    const bool empty = std::find(dims.begin(), dims.end(), hsize_t{0}) != dims.end();
    if (!empty) {
      // Chunks of ~kChunkBytes: whole trailing dimensions while they fit, then a run of the
      // first dimension that does not fit (for [V, ...] that is a block of vertices).
      std::vector<hsize_t> chunk(dims.size(), 1);
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
    if (!empty)
      check(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf), "cannot write " + name);
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
  std::string msg_file_;
  hid_t file_;
  bool checksum_data_;
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
                   OnDisk on_disk = OnDisk::current) {
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

  const std::string prefix = final_path.filename().string() + ".tmp." + detail::host_tag() + ".";
  const std::filesystem::path tmp = dir / detail::temporary_name(prefix);
  detail::remove_stale_temporaries(dir, prefix);

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

    Writer w(msg_file, f.get(), on_disk == OnDisk::current);
    Hid root = detail::group_id(H5Gopen2(f.get(), "/", H5P_DEFAULT));
    if (!root.valid()) fail("cannot open the root group");
    if (add_format) {
      w.write_attr(root.get(), {std::string(names::kFormat), std::string(kFormatName)}, "the root group");
      w.write_attr(root.get(), {std::string(names::kFormatVersion), int64_t{kFormatVersion}}, "the root group");
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
} // namespace testing

} // namespace prt::formats
