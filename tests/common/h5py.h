// h5py from tests: find a python3 that has it, and add attributes to a file the way another tool
// would, for the tests that check that such attributes are kept and shown, fixed- or
// variable-length strings alike (formats/SCHEMA.md, "Extra attributes").
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

// How add_h5py_notes stores its strings: fixed-length UTF-8 (prtbake's own kind), or h5py's
// defaults for Python values, which are variable-length strings, their text in the file's
// global heap (formats/prtfile.h, "Which files the reader opens").
enum class H5pyStrings { fixed_length, variable_length };

// Adds string attributes named "note" with h5py: on the root ("root note ✓"), on the group
// `group` ("group note") and on the dataset `dataset` ("dataset note"). With variable_length
// also, on the root, as h5py stores a list of str, "tags" = ["a", "bb", "ccc ✓"] (an array of
// variable-length strings), and, fixed-length beside them, "fixed" = "fixed text". Returns
// what python printed on failure ("" on success).
inline std::string add_h5py_notes(const std::string& python, const std::filesystem::path& file,
                                  const std::string& group, const std::string& dataset,
                                  H5pyStrings kind = H5pyStrings::fixed_length) {
  const std::filesystem::path dir = file.parent_path();
  const std::string script = "import h5py, sys\n"
                             "fixed = sys.argv[4] == 'fixed'\n"
                             "def note(obj, text):\n"
                             "    if fixed:\n"
                             "        b = text.encode('utf-8')\n"
                             "        obj.attrs.create('note', b, dtype=h5py.string_dtype('utf-8', len(b)))\n"
                             "    else:\n"
                             "        obj.attrs['note'] = text\n"
                             "    assert (h5py.check_string_dtype(obj.attrs.get_id('note').dtype).length is None) != fixed\n"
                             "f = h5py.File(sys.argv[1], 'r+')\n"
                             "note(f, 'root note \\u2713')\n"
                             "note(f[sys.argv[2]], 'group note')\n"
                             "note(f[sys.argv[3]], 'dataset note')\n"
                             "if not fixed:\n"
                             "    f.attrs['tags'] = ['a', 'bb', 'ccc \\u2713']\n"
                             "    assert h5py.check_string_dtype(f.attrs.get_id('tags').dtype).length is None\n"
                             "    f.attrs.create('fixed', b'fixed text', dtype=h5py.string_dtype('utf-8', 10))\n"
                             "f.close()\n";
  const std::filesystem::path py = dir / "add_notes.py";
  std::ofstream(py) << script;
  const ToolRun r = run_tool(python, "'" + py.string() + "' '" + file.string() + "' '" + group + "' '" + dataset + "' " +
                                         (kind == H5pyStrings::fixed_length ? "fixed" : "variable"),
                             dir);
  return r.code == 0 ? std::string() : "python failed (" + std::to_string(r.code) + "): " + r.out + r.err;
}

// Runs python `statements` with `f` = h5py.File(file, 'r+') open (closed after them), as another
// tool would edit the file. Returns what python printed on failure ("" on success).
inline std::string edit_with_h5py(const std::string& python, const std::filesystem::path& file,
                                  const std::string& statements) {
  const std::filesystem::path py = file.parent_path() / "edit.py";
  std::ofstream(py) << "import h5py, numpy, sys\nf = h5py.File(sys.argv[1], 'r+')\n" << statements << "\nf.close()\n";
  const ToolRun r = run_tool(python, "'" + py.string() + "' '" + file.string() + "'", file.parent_path());
  return r.code == 0 ? std::string() : "python failed (" + std::to_string(r.code) + "): " + r.out + r.err;
}

} // namespace prt::testing
