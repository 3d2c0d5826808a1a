# PRT_FUZZ: the libFuzzer build (tests/fuzz/, docs/RELIABILITY.md "Fuzzing"). Included by the root
# CMakeLists.txt before any component, so that every library the fuzz targets link (prtshade,
# formats, the loader, libbake) is compiled with the same instrumentation as the targets:
# AddressSanitizer, UndefinedBehaviorSanitizer (no recovery: the first report aborts) and
# libFuzzer's coverage (fuzzer-no-link; the targets link the fuzzer itself). System libraries
# (HDF5, OpenEXR, tinygltf, OpenMesh, Embree, TBB) stay uninstrumented: ASan still intercepts
# their malloc/free, so a crash or a bad free inside them is reported, but not an overflow
# within a heap block they own.
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang" OR NOT CMAKE_C_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "PRT_FUZZ needs clang for C and C++ (libFuzzer); this is "
                      "${CMAKE_C_COMPILER_ID}/${CMAKE_CXX_COMPILER_ID}. Use the preset: cmake --preset fuzz "
                      "(clang-14, libclang-rt-14-dev)")
endif()
if(PRT_SANITIZE)
  message(FATAL_ERROR "PRT_FUZZ already builds with ASan + UBSan; turn PRT_SANITIZE off")
endif()
set(PRT_FUZZ_SANITIZERS address,undefined)
add_compile_options(-fsanitize=fuzzer-no-link,${PRT_FUZZ_SANITIZERS} -fno-sanitize-recover=undefined
                    -fno-omit-frame-pointer)
add_link_options(-fsanitize=${PRT_FUZZ_SANITIZERS})
