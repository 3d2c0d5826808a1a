# Script of the package_deb test (see CMakeLists.txt): cpack -G DEB, then the package as dpkg sees it.
foreach(v BUILD_DIR WORK_DIR CPACK DPKG_DEB DPKG VERSION)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "package_deb.cmake: -D${v}=... missing")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})

include(${CMAKE_CURRENT_LIST_DIR}/run_steps.cmake)  # run(), expect()

execute_process(COMMAND ${CMAKE_COMMAND} -E chdir ${BUILD_DIR} ${CPACK} -G DEB -B ${WORK_DIR}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cpack -G DEB failed (${rc}):\n${out}\n${err}")
endif()
file(GLOB debs ${WORK_DIR}/*.deb)
list(LENGTH debs n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "cpack made ${n} .deb files, not 1: '${debs}'\n${out}")
endif()
get_filename_component(deb_name ${debs} NAME)
expect("${deb_name}" "^prtbake_${VERSION}_[a-z0-9]+\\.deb$" "the package's file name")

# Control fields: name, version, maintainer, and the run-time libraries dpkg-shlibdeps found.
run("dpkg-deb -I" ${DPKG_DEB} -I ${debs})
set(info "${last_output}")
expect("${info}" "\n Package: prtbake\n" "dpkg-deb -I")
expect("${info}" "\n Version: ${VERSION}\n" "dpkg-deb -I")
expect("${info}" "\n Maintainer: [^\n]+<[^\n]+@[^\n]+>\n" "dpkg-deb -I")
foreach(lib libhdf5 libembree3 libtbb libopenexr libpng16 libstdc\\+\\+6)
  expect("${info}" "\n Depends: [^\n]*${lib}" "dpkg-deb -I (Depends)")
endforeach()

# Files: the tools, the library, its headers and its CMake package.
run("dpkg-deb -c" ${DPKG_DEB} -c ${debs})
set(files "${last_output}")
set(wanted usr/bin/prtbake usr/bin/prtdump usr/bin/prtview usr/lib[^\n]*/libprtshade\\.a
    usr/include/prtshade/sh\\.h usr/lib[^\n]*/cmake/prtshade/prtshadeConfig\\.cmake
    usr/share/prtshade/shaders/sh\\.glsl)
if(LOADER)
  list(APPEND wanted usr/lib[^\n]*/libprtshade_hdf5\\.a usr/include/prtshade/loader\\.h)
endif()
foreach(f ${wanted})
  expect("${files}" " \\./${f}\n" "dpkg-deb -c")
endforeach()

# The tools as the package installs them, from a scratch root.
run("dpkg -x" ${DPKG} -x ${debs} ${WORK_DIR}/root)
foreach(tool prtbake prtdump prtview)
  run("${tool} --version from the package" ${WORK_DIR}/root/usr/bin/${tool} --version)
  expect("${last_output}" "^${tool} ${VERSION}\n" "${tool} --version from the package")
endforeach()
message(STATUS "${deb_name}:\n${info}")
