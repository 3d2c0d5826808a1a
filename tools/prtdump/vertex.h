// tools/prtdump/vertex.h — `prtdump --vertex I [--object NAME]`: every per-vertex value of one
// vertex of the root layout or of a scene object, as text laid out by the trailing axes (SH
// bands, RGB channels) or as JSON nested by them (formats/SCHEMA.md: the per-vertex datasets).
#pragma once

#include "values.h"

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>

namespace prt::tool::dump {

// The vertex set --vertex prints: the root layout (prefix "") or a scene object's
// ("/objects/<name>", shown as its label).
struct VertexSetRef {
  std::string prefix;
  std::string label;  // empty for the root layout
};

// The vertex set --vertex reads: the root layout, or with --object the scene object it names (by
// its node path or its stored name). One line naming the file for every mistake.
VertexSetRef vertex_set(const pf::File& f, const std::string& file, const std::optional<std::string>& object);

// V of a vertex set, from its positions.
uint64_t vertex_count(const pf::File& f, const std::string& file, const VertexSetRef& set);

// Every per-vertex value of vertex `vertex` (of V) of the set, as text (`prtdump --vertex`) and
// as one JSON object (with --json).
void vertex_text(std::ostream& os, const std::string& path, const pf::File& f, const VertexSetRef& set, uint64_t vertex,
                 uint64_t V);
Json vertex_json(const std::string& path, const pf::File& f, const VertexSetRef& set, uint64_t vertex, uint64_t V);

} // namespace prt::tool::dump
