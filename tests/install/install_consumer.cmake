# Script of the install_consumer test (see CMakeLists.txt): install, check the installed layout,
# run the installed tools from the prefix (--version, --help, a small bake read back by prtdump
# and drawn by prtview), configure + build + run the consumers against the installed package
# only: the core alone (with HDF5 and oneTBB made unfindable, so the core package needs neither),
# then with the hdf5 component, whose program loads the file the installed prtbake baked.
foreach(v BUILD_DIR CONSUMER_SOURCE WORK_DIR GENERATOR CXX_COMPILER VERSION)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "install_consumer.cmake: -D${v}=... missing")
  endif()
endforeach()
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})

include(${CMAKE_CURRENT_LIST_DIR}/run_steps.cmake)  # run(), expect()

run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# The installed layout: tools, headers, library, package files (and the GLSL mirrors when the
# source tree has them).
file(GLOB lib ${prefix}/lib*/libprtshade.*)
set(expected bin/prtbake bin/prtdump bin/prtview
    include/prtshade/sh.h include/prtshade/shade.h include/prtshade/fiv.h include/prtshade/prtshade.h)
if(LOADER)
  list(APPEND expected include/prtshade/loader.h include/formats/prtfile.h include/formats/asset.h)
endif()
foreach(f ${expected})
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "installed tree lacks ${f}")
  endif()
endforeach()
file(GLOB config ${prefix}/lib*/cmake/prtshade/prtshadeConfig.cmake)
file(GLOB version ${prefix}/lib*/cmake/prtshade/prtshadeConfigVersion.cmake)
if(NOT lib OR NOT config OR NOT version)
  message(FATAL_ERROR "installed tree lacks the library or the CMake package (lib: '${lib}', config: '${config}')")
endif()
if(LOADER)
  file(GLOB loader_lib ${prefix}/lib*/libprtshade_hdf5.*)
  file(GLOB loader_targets ${prefix}/lib*/cmake/prtshade/prtshade_hdf5Targets.cmake)
  if(NOT loader_lib OR NOT loader_targets)
    message(FATAL_ERROR "installed tree lacks the loader (lib: '${loader_lib}', targets: '${loader_targets}')")
  endif()
endif()
# Every mirror and the bodies they include: GLSL, HLSL and the shared .inc files.
file(GLOB glsl_source ${SHADER_SOURCE}/*.glsl ${SHADER_SOURCE}/*.hlsl ${SHADER_SOURCE}/*.inc)
foreach(g ${glsl_source})
  get_filename_component(name ${g} NAME)
  if(NOT EXISTS ${prefix}/share/prtshade/shaders/${name})
    message(FATAL_ERROR "installed tree lacks share/prtshade/shaders/${name}")
  endif()
endforeach()

# The tools, run from the prefix in a directory of their own: nothing they need at run time may
# come from the source or build tree.
set(run_dir ${WORK_DIR}/run)
file(MAKE_DIRECTORY ${run_dir})
function(run_tool what expect)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${run_dir}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT "${out}${err}" MATCHES "${expect}")
    message(FATAL_ERROR "installed ${what} (exit ${rc}) did not print '${expect}':\n${out}\n${err}")
  endif()
endfunction()
foreach(tool prtbake prtdump prtview)
  run_tool("${tool} --version" "^${tool} ${VERSION}\n" ${prefix}/bin/${tool} --version)
  run_tool("${tool} --help" "${tool}" ${prefix}/bin/${tool} --help)
endforeach()
# A tetrahedron over a square: 8 vertices, AO only, a pinned small bake without the error check.
file(WRITE ${run_dir}/tiny.obj "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nf 1 3 2\nf 1 4 3\n"
  "v 0 0.5 0\nv 1 0.5 0\nv 0 0.5 1\nv 0 1.5 0\nf 5 6 7\nf 5 8 6\nf 5 7 8\nf 6 8 7\n")
run_tool("prtbake vertex" "wrote tiny.prt.h5" ${prefix}/bin/prtbake vertex tiny.obj --ao --samples 256
         --report 0 -o tiny.prt.h5)
run_tool("prtdump" "schema +valid" ${prefix}/bin/prtdump tiny.prt.h5)
run_tool("prtview" "wrote look.png" ${prefix}/bin/prtview tiny.prt.h5 --size 64x48 -o look.png)

# A consumer that sees only the installed prefix. A sanitizer build (PRT_SANITIZE) installs an
# instrumented library, so its consumer must link the sanitizer runtimes too.
set(extra)
if(SANITIZE)
  list(APPEND extra -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
endif()
set(consumer_args -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF ${extra})
# The core: find_package(prtshade) must not look for the loader's dependencies.
run("consumer configure (core)" ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE} -B ${WORK_DIR}/core ${consumer_args}
    -DCMAKE_DISABLE_FIND_PACKAGE_HDF5=ON -DCMAKE_DISABLE_FIND_PACKAGE_TBB=ON)
run("consumer build (core)" ${CMAKE_COMMAND} --build ${WORK_DIR}/core)
run("consumer run (core)" ${WORK_DIR}/core/prtshade_consumer)
message(STATUS "consumer output:\n${last_output}")
if(NOT last_output MATCHES "prtshade consumer: ok")
  message(FATAL_ERROR "consumer did not report success:\n${last_output}")
endif()
if(NOT LOADER)
  return()
endif()
# The loader: find_package(prtshade COMPONENTS hdf5) finds what the static libraries link.
run("consumer configure (hdf5)" ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE} -B ${WORK_DIR}/hdf5 ${consumer_args}
    -DCONSUMER_LOADER=ON)
run("consumer build (hdf5)" ${CMAKE_COMMAND} --build ${WORK_DIR}/hdf5)
run("consumer run (hdf5)" ${WORK_DIR}/hdf5/prtshade_loader_consumer ${run_dir}/tiny.prt.h5 8)
message(STATUS "loader consumer output:\n${last_output}")
if(NOT last_output MATCHES "prtshade loader consumer: ok")
  message(FATAL_ERROR "loader consumer did not report success:\n${last_output}")
endif()
