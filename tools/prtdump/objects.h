// tools/prtdump/objects.h — the scene objects of a file as stored, each with the one spelling
// people read (formats::object_label: a glTF object's node path, never its HDF5 name), and which
// object each dataset and group belongs to (/objects, /report/objects, the FIV occluders:
// formats/SCHEMA.md), so every section of prtdump lists a dataset under its object.
#pragma once

#include <formats/asset.h>

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace prt::tool::dump {

namespace pf = prt::formats;

// The scene objects of a file as stored (a file that fails the schema has no asset): each
// object's stored name and, for a glTF scene's, its node path. Object names are printed as
// formats::object_label gives them (the node path, "node0/node13/node71"), never as the HDF5
// name ("node0|node13|node71"), which appears only where it is labelled as one.
struct FileObject {
  std::string name;                      // as stored: /objects/<name>
  std::optional<std::string> node_path;  // the group's node_path attribute, when it is a string
  std::string label() const { return pf::object_label(name, node_path); }
};

std::vector<FileObject> file_objects(const pf::File& f);

// A dataset path that belongs to scene object `object` (its vertex set, its report, its FIV
// shells), and the path within it as printed under the object: "mesh/positions", "report/ao",
// "fiv/shells", "report/fiv".
struct ObjectPath {
  const FileObject* object = nullptr;
  std::string rest;
};
ObjectPath object_path(const std::vector<FileObject>& objects, std::string_view path);

// "object node0/node13/node71 (stored as /objects/node0|node13|node71)": the heading of an object's lines.
std::string object_heading(const FileObject& o);

// Datasets in the order printed: the ones of no object first (file order), then each object's.
struct DatasetGroups {
  std::vector<const pf::Dataset*> loose;
  std::vector<std::pair<const FileObject*, std::vector<std::pair<const pf::Dataset*, std::string>>>> objects;
};
DatasetGroups group_datasets(const pf::File& f, const std::vector<FileObject>& objects);

} // namespace prt::tool::dump
