// h5util.h (private) — RAII for HDF5 identifiers, the process-wide HDF5 lock and the
// conversion of HDF5 error stacks into FormatError text. Nothing here is public API.
#pragma once

#include <hdf5.h>

#include <mutex>
#include <string>
#include <utility>

namespace prt::formats::detail {

// Serial HDF5 is not thread-safe: every entry point holds this lock while it calls HDF5.
std::mutex& hdf5_mutex();

// Turns off HDF5's automatic error-stack printing (we report errors ourselves). Call with
// hdf5_mutex() held, at every entry point (cheap; also undoes anyone who turned it back on).
void silence_hdf5_errors();

// The most specific message on HDF5's current error stack ("" when empty), then clears it.
std::string take_hdf5_error();

// A move-only owner of an hid_t that calls the matching H5*close on destruction.
class Hid {
public:
  using Closer = herr_t (*)(hid_t);
  Hid() = default;
  Hid(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Hid(const Hid&) = delete;
  Hid& operator=(const Hid&) = delete;
  Hid(Hid&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), closer_(o.closer_) {}
  Hid& operator=(Hid&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
      closer_ = o.closer_;
    }
    return *this;
  }
  ~Hid() { reset(); }

  hid_t get() const noexcept { return id_; }
  bool valid() const noexcept { return id_ >= 0; }
  // Closes now and returns the close call's status (negative on failure, e.g. a failed flush).
  herr_t close() noexcept {
    herr_t status = 0;
    if (id_ >= 0 && closer_ != nullptr) status = closer_(id_);
    id_ = H5I_INVALID_HID;
    return status;
  }

private:
  void reset() noexcept { (void)close(); }
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

inline Hid file_id(hid_t id) { return {id, &H5Fclose}; }
inline Hid group_id(hid_t id) { return {id, &H5Gclose}; }
inline Hid dataset_id(hid_t id) { return {id, &H5Dclose}; }
inline Hid space_id(hid_t id) { return {id, &H5Sclose}; }
inline Hid type_id(hid_t id) { return {id, &H5Tclose}; }
inline Hid attr_id(hid_t id) { return {id, &H5Aclose}; }
inline Hid plist_id(hid_t id) { return {id, &H5Pclose}; }
inline Hid object_id(hid_t id) { return {id, &H5Oclose}; }

// IEEE 754 binary16, little-endian (sign bit 15, exponent bits 10–14 with bias 15, mantissa bits
// 0–9): the file and memory type of float16 datasets (v8), as h5py writes numpy's float16.
// Invalid (get() < 0) when HDF5 refuses a step.
Hid make_float16_type();
// True when `type` is that layout (either byte order): the only 2-byte float the reader accepts.
bool is_float16_layout(hid_t type);

// A fixed-length, NUL-padded UTF-8 string type of `bytes` bytes (at least 1): the type of every
// string attribute we write. Fixed-length strings live inside the (checksummed) object header;
// variable-length ones live in the global heap, which HDF5 1.10 reads without bounds checks,
// so a damaged file could crash a reader that lets HDF5 read them. The writer therefore never
// writes them, and the reader reads those that other tools add (h5py str attributes) with its
// own bounds-checked code (global_heap.h).
Hid make_utf8_string_type(std::size_t bytes);

} // namespace prt::formats::detail
