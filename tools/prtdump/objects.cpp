// tools/prtdump/objects.cpp — scene objects and the datasets of each (contract: objects.h).
#include "objects.h"

#include <formats/names.h>

#include <algorithm>

namespace prt::tool::dump {

namespace names = prt::formats::names;

namespace {

const FileObject* find_file_object(const std::vector<FileObject>& objects, std::string_view name) {
  for (const FileObject& o : objects)
    if (o.name == name) return &o;
  return nullptr;
}

} // namespace

std::vector<FileObject> file_objects(const pf::File& f) {
  const std::string dir = std::string(names::kObjects) + "/";
  std::vector<FileObject> out;
  auto add = [&](std::string_view prefix) -> FileObject* {
    if (!prefix.starts_with(dir)) return nullptr;
    const std::string_view name = prefix.substr(dir.size());
    if (name.empty() || name.find('/') != std::string_view::npos) return nullptr;
    for (FileObject& o : out)
      if (o.name == name) return &o;
    return &out.emplace_back(FileObject{std::string(name), std::nullopt});
  };
  for (const pf::Dataset& d : f.datasets) add(pf::vertex_set_of(d.path));
  for (const auto& [g, attrs] : f.group_attrs)
    if (FileObject* o = add(g))
      if (const pf::Attr* a = pf::find_attr(attrs, names::kNodePath))
        if (const auto* s = std::get_if<std::string>(&a->value)) o->node_path = *s;
  std::sort(out.begin(), out.end(), [](const FileObject& x, const FileObject& y) { return x.name < y.name; });
  return out;
}

ObjectPath object_path(const std::vector<FileObject>& objects, std::string_view path) {
  const std::string objects_dir = std::string(names::kObjects) + "/";
  const std::pair<std::string, std::string> dirs[] = {
      {objects_dir, ""},
      {std::string(names::kReport) + objects_dir, "report/"},
      {std::string(names::kOccluders) + "/", "fiv/"},
      {std::string(names::kReportFiv) + "/", "report/fiv"}};
  for (const auto& [dir, shown] : dirs) {
    if (!path.starts_with(dir)) continue;
    const std::string_view tail = path.substr(dir.size());
    const std::size_t slash = tail.find('/');
    const FileObject* o = find_file_object(objects, tail.substr(0, slash));
    if (o == nullptr) continue;
    if (slash == std::string_view::npos) return {o, shown.ends_with('/') ? shown.substr(0, shown.size() - 1) : shown};
    return {o, shown + std::string(tail.substr(slash + 1))};
  }
  return {};
}

std::string object_heading(const FileObject& o) {
  const std::string label = o.label();
  return "object " + label + (label != o.name ? " (stored as " + std::string(names::kObjects) + "/" + o.name + ")" : "");
}

DatasetGroups group_datasets(const pf::File& f, const std::vector<FileObject>& objects) {
  DatasetGroups g;
  for (const FileObject& o : objects) g.objects.push_back({&o, {}});
  for (const pf::Dataset& d : f.datasets) {
    const ObjectPath op = object_path(objects, d.path);
    if (op.object == nullptr) {
      g.loose.push_back(&d);
      continue;
    }
    for (auto& [o, list] : g.objects)
      if (o == op.object) list.emplace_back(&d, op.rest);
  }
  return g;
}

} // namespace prt::tool::dump
