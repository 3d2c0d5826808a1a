// h5py from tests: find a python3 that has it, and add attributes to a file the way another tool
// would (h5py `str` attributes are variable-length strings), for the tests that check that such
// attributes are kept and shown (formats/SCHEMA.md, "Extra attributes").
#pragma once

#include <run_tool.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace prt::testing {

// A python3 that imports h5py, or "" (then the caller skips). The first Python on PATH may be a
// private one (pyenv) without h5py; Debian's has it when python3-h5py is installed.
inline std::string python_with_h5py(const std::filesystem::path& capture_dir) {
  for (const char* candidate : {"python3", "/usr/bin/python3"})
    if (run_tool(candidate, "-c 'import h5py'", capture_dir).code == 0) return candidate;
  return "";
}

// Adds variable-length string attributes named "note" with h5py: on the root ("root note ✓"),
// on the group `group` ("group note") and on the dataset `dataset` ("dataset note"). Returns
// what python printed on failure ("" on success).
inline std::string add_h5py_notes(const std::string& python, const std::filesystem::path& file,
                                  const std::string& group, const std::string& dataset) {
  const std::filesystem::path dir = file.parent_path();
  const std::string script = "import h5py, sys\n"
                             "f = h5py.File(sys.argv[1], 'r+')\n"
                             "f.attrs['note'] = 'root note \\u2713'\n"
                             "f[sys.argv[2]].attrs['note'] = 'group note'\n"
                             "f[sys.argv[3]].attrs['note'] = 'dataset note'\n"
                             "assert h5py.check_string_dtype(f.attrs.get_id('note').dtype).length is None\n"
                             "f.close()\n";
  const std::filesystem::path py = dir / "add_notes.py";
  std::ofstream(py) << script;
  const ToolRun r = run_tool(python, "'" + py.string() + "' '" + file.string() + "' '" + group + "' '" + dataset + "'",
                             dir);
  return r.code == 0 ? std::string() : "python failed (" + std::to_string(r.code) + "): " + r.out + r.err;
}

} // namespace prt::testing
