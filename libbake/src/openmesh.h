// libbake/src/openmesh.h — the OpenMesh 9 headers libbake uses (halfedge meshes and Loop
// subdivision; mesh files are read by our own readers, see mesh_io.cpp), included once with the warnings they raise under
// prtbake's flags (-Wshadow, -Woverloaded-virtual, ...) silenced for them alone. Private to libbake.
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
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#pragma GCC diagnostic pop
