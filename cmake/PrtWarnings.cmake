# prt_warnings: an INTERFACE target every prtbake target links privately (after pbrt's
# pbrt_warnings). PRT_WARNINGS_AS_ERRORS turns them into errors (the ci preset does).
add_library(prt_warnings INTERFACE)
target_compile_options(prt_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Wunused
  -Woverloaded-virtual -Wnull-dereference -Wimplicit-fallthrough -Wno-missing-field-initializers)
# GCC 12 at -O3 reports -Wrestrict on plain std::string assignments inside libstdc++
# (GCC bug 105329, fixed in 13): a false positive we cannot silence at the call site.
target_compile_options(prt_warnings INTERFACE
  $<$<AND:$<CXX_COMPILER_ID:GNU>,$<VERSION_LESS:$<CXX_COMPILER_VERSION>,13>>:-Wno-restrict>)
if(PRT_WARNINGS_AS_ERRORS)
  target_compile_options(prt_warnings INTERFACE -Werror)
endif()
if(PRT_SANITIZE)
  target_compile_options(prt_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(prt_warnings INTERFACE -fsanitize=address,undefined)
endif()
