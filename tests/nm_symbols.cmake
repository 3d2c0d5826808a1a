# nm_symbols.cmake — included by the checks that read a static library's symbols
# (check_silent.cmake, check_layers.cmake).
#   prt_nm_matches(<nm> <library.a> <regex> <out_hits> <out_count> [UNDEFINED])
# lists the library's symbols with nm, demangled (a shared symbol's version suffix, such as
# "@GLIBC_2.2.5", dropped; UNDEFINED: only those it needs from elsewhere), sets <out_count> to
# their number and <out_hits> to the lines "\n  <object>: <symbol>" of those matching <regex>.
# Stops with an error when nm fails or lists none (not a static library, or nm's format changed):
# a check that read nothing must not pass.
function(prt_nm_matches nm lib regex out_hits out_count)
  set(flags -A -C)
  if(ARGN STREQUAL "UNDEFINED")
    list(APPEND flags -u)
  endif()
  execute_process(COMMAND ${nm} ${flags} ${lib} OUTPUT_VARIABLE listing RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${nm} ${lib} failed: ${err}")
  endif()
  string(REPLACE "\n" ";" lines "${listing}")
  set(count 0)
  set(hits "")
  foreach(line IN LISTS lines)
    # "<archive>:<object>:<address> <type> <symbol>" (no address for undefined symbols)
    if(line MATCHES "^[^:]*:([^:]+): *[0-9a-f]* +[A-Za-z] (.+)$")
      math(EXPR count "${count} + 1")
      set(object "${CMAKE_MATCH_1}")
      string(REGEX REPLACE "@.*$" "" symbol "${CMAKE_MATCH_2}")
      if(symbol MATCHES "${regex}")
        string(APPEND hits "\n  ${object}: ${symbol}")
      endif()
    endif()
  endforeach()
  if(count EQUAL 0)
    message(FATAL_ERROR "${nm} ${flags} ${lib} listed no '<archive>:<object>: <type> <symbol>' lines")
  endif()
  set(${out_hits} "${hits}" PARENT_SCOPE)
  set(${out_count} ${count} PARENT_SCOPE)
endfunction()
