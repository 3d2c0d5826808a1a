# Script of the install_consumer test (see CMakeLists.txt): install, check the installed layout,
# configure + build + run the consumer against the installed package only.
foreach(v BUILD_DIR CONSUMER_SOURCE WORK_DIR GENERATOR CXX_COMPILER)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "install_consumer.cmake: -D${v}=... missing")
  endif()
endforeach()
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix} --component prtshade)

# The installed layout: headers, library, package files (and the GLSL mirrors when the source
# tree has them).
file(GLOB lib ${prefix}/lib*/libprtshade.*)
foreach(f include/prtshade/sh.h include/prtshade/shade.h include/prtshade/fiv.h include/prtshade/prtshade.h)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "installed tree lacks ${f}")
  endif()
endforeach()
file(GLOB config ${prefix}/lib*/cmake/prtshade/prtshadeConfig.cmake)
file(GLOB version ${prefix}/lib*/cmake/prtshade/prtshadeConfigVersion.cmake)
if(NOT lib OR NOT config OR NOT version)
  message(FATAL_ERROR "installed tree lacks the library or the CMake package (lib: '${lib}', config: '${config}')")
endif()
# Every mirror and the bodies they include: GLSL, HLSL and the shared .inc files.
file(GLOB glsl_source ${SHADER_SOURCE}/*.glsl ${SHADER_SOURCE}/*.hlsl ${SHADER_SOURCE}/*.inc)
foreach(g ${glsl_source})
  get_filename_component(name ${g} NAME)
  if(NOT EXISTS ${prefix}/share/prtshade/shaders/${name})
    message(FATAL_ERROR "installed tree lacks share/prtshade/shaders/${name}")
  endif()
endforeach()

# A consumer that sees only the installed prefix. A sanitizer build (PRT_SANITIZE) installs an
# instrumented library, so its consumer must link the sanitizer runtimes too.
set(extra)
if(SANITIZE)
  list(APPEND extra -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
endif()
run("consumer configure" ${CMAKE_COMMAND} -S ${CONSUMER_SOURCE} -B ${WORK_DIR}/build -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF ${extra})
run("consumer build" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run("consumer run" ${WORK_DIR}/build/prtshade_consumer)
message(STATUS "consumer output:\n${last_output}")
if(NOT last_output MATCHES "prtshade consumer: ok")
  message(FATAL_ERROR "consumer did not report success:\n${last_output}")
endif()
