# What a lower layer must not pull in, read from what the build produced (docs/ARCHITECTURE.md
# §2): the runtime loader's link line and the symbols of the static libraries under it. The
# configure-time check (cmake/PrtLayers.cmake) reads the target graph; this one reads the
# generated files, so a dependency that reaches the link some other way is caught too.
#   cmake -DLINK_TXT=<link.txt> -DREQUIRE=<regex;...> -DFORBID=<regex> -P check_layers.cmake
#     the link command must match every REQUIRE (so the right command was read) and not FORBID;
#   cmake -DNM=<nm> -DLIBS=<a.a;...> -DFORBID=<regex> -P check_layers.cmake
#     no symbol (defined or undefined, demangled) of the libraries may match FORBID.
if(NOT FORBID OR (NOT LINK_TXT AND NOT (NM AND LIBS)))
  message(FATAL_ERROR "usage: cmake -DLINK_TXT=<link.txt> -DREQUIRE=<regex;...> -DFORBID=<regex> -P check_layers.cmake\n"
                      "   or: cmake -DNM=<nm> -DLIBS=<a.a;...> -DFORBID=<regex> -P check_layers.cmake")
endif()

if(LINK_TXT)
  if(NOT EXISTS "${LINK_TXT}")
    message(FATAL_ERROR "${LINK_TXT} does not exist (not a Makefile build, or the target is not built yet)")
  endif()
  file(READ "${LINK_TXT}" line)
  foreach(required IN LISTS REQUIRE)
    if(NOT line MATCHES "${required}")
      message(FATAL_ERROR "${LINK_TXT} does not match '${required}': not the link command expected:\n${line}")
    endif()
  endforeach()
  string(REGEX MATCHALL "[^ \n]*(${FORBID})[^ \n]*" hits "${line}")
  if(hits)
    list(JOIN hits "\n  " shown)
    message(FATAL_ERROR "${LINK_TXT} links what this layer must not:\n  ${shown}")
  endif()
  message(STATUS "${LINK_TXT}: nothing matches '${FORBID}'")
endif()

if(NM AND LIBS)
  include(${CMAKE_CURRENT_LIST_DIR}/nm_symbols.cmake)
  foreach(lib IN LISTS LIBS)
    prt_nm_matches(${NM} ${lib} "${FORBID}" hits count)
    if(hits)
      message(FATAL_ERROR "${lib} holds or needs symbols this layer must not (object: symbol):${hits}")
    endif()
    message(STATUS "${lib}: none of its ${count} symbols matches '${FORBID}'")
  endforeach()
endif()
