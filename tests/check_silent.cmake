# A library that must stay silent (libbake, view: docs/ARCHITECTURE.md §9) must
# not reference the C or C++ standard streams or the functions that write to them. Lists the
# static library's undefined symbols with nm and fails naming each object file and symbol.
# Writing into buffers (snprintf, std::ostringstream) and into files the caller named
# (std::ofstream, fopen + fwrite on that FILE*) is fine and not matched here; fwrite is matched
# because it is the usual way to reach stdout by hand, and files are written through the
# formats/, OpenEXR and libpng libraries instead. OpenMesh's message streams (omerr, omlog,
# omout, which write to std::cerr inside libOpenMeshCore) are referenced by libbake's subdivision
# through OpenMesh's inline code; libbake/mesh/src/openmesh.h disables them for the process and the
# bake test SilentLibrary.* checks at run time that nothing is printed.
#   cmake -DNM=<nm> -DLIB=<libx.a> -P check_silent.cmake
if(NOT NM OR NOT LIB)
  message(FATAL_ERROR "usage: cmake -DNM=<nm> -DLIB=<library.a> -P check_silent.cmake")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/nm_symbols.cmake)
# The C streams and their writers (with glibc's _FORTIFY_SOURCE variants), the C++ streams.
set(forbidden "printf|vprintf|fprintf|vfprintf|puts|fputs|putchar|putc|fputc|fwrite|perror|stdout|stderr|_IO_putc|__printf_chk|__vprintf_chk|__fprintf_chk|__vfprintf_chk|std::cout|std::cerr|std::clog|std::wcout|std::wcerr|std::wclog")
prt_nm_matches(${NM} ${LIB} "^(${forbidden})$" hits count UNDEFINED)
if(hits)
  message(FATAL_ERROR "${LIB} writes to the terminal (object: undefined symbol):${hits}")
endif()
message(STATUS "${LIB}: none of its ${count} undefined symbols writes to stdout, stderr or the standard streams")
