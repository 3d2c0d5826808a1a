// libbake/mesh/src/openmesh.h — the OpenMesh 9 headers libbake uses (halfedge meshes and Loop
// subdivision; mesh files are read by our own readers, see mesh_io.cpp), included once with the
// warnings they raise under prtbake's flags (-Wshadow, -Woverloaded-virtual, ...) silenced for
// them alone. Private to libbake.
//
// libbake prints nothing (bake/core/progress.h): OpenMesh's own message streams (omerr, omlog, omout;
// e.g. "PolyMeshT::add_face: complex vertex" when it refuses a face) are switched off for the
// process as soon as a file including this header is linked in. Whatever OpenMesh refuses is
// turned into an InputError with our own message where it happens (subdivide.cpp).
#pragma once

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Woverloaded-virtual"
#pragma GCC diagnostic ignored "-Wnull-dereference"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wcast-align"
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#pragma GCC diagnostic pop

namespace prt::bake::openmesh_detail {
inline const bool kOpenMeshSilenced = [] {
  ::omerr().disable();
  ::omlog().disable();
  ::omout().disable();
  return true;
}();
} // namespace prt::bake::openmesh_detail
