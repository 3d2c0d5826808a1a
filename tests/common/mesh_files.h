// Scratch mesh files for the mesh-input tests (bake/mesh/mesh.h): writing them, and the contract every
// refused file must meet (a one-line InputError naming the file and the defect).
#pragma once

#include <bake/core/error.h>
#include <bake/mesh/mesh.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace prt::testing {

// PRT_TEST_TMP/<name>, created.
inline std::filesystem::path test_dir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(PRT_TEST_TMP) / name;
  std::filesystem::create_directories(dir);
  return dir;
}

// `bytes` written to dir/name (replacing it); a failed write fails the test.
inline std::filesystem::path write_test_file(const std::filesystem::path& dir, const std::string& name, const std::string& bytes) {
  const std::filesystem::path p = dir / name;
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  EXPECT_TRUE(out.good()) << "could not write " << p;
  return p;
}

// load_mesh(path) must throw InputError whose one-line what() names the file and contains `defect_part`.
inline void expect_input_error(const std::filesystem::path& path, const std::string& defect_part) {
  SCOPED_TRACE(path.filename().string());
  try {
    bake::load_mesh(path);
    ADD_FAILURE() << path << " was accepted; expected an error containing '" << defect_part << "'";
  } catch (const bake::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path.string()), std::string::npos) << "what() must name the file: " << what;
    EXPECT_NE(what.find(defect_part), std::string::npos) << "what() must name the defect: " << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
  }
}

// build_mesh(polygons, "generated") must throw InputError "generated: <...defect_part...>".
inline void expect_build_defect(const bake::Polygons& polygons, const std::string& defect_part) {
  try {
    (void)bake::build_mesh(polygons, "generated");
    ADD_FAILURE() << "accepted; expected '" << defect_part << "'";
  } catch (const bake::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("generated: " + defect_part), std::string::npos) << e.what();
  }
}

} // namespace prt::testing
