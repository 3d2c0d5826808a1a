# CPack: `cpack -G DEB` in a build directory makes one Debian package, prtbake_<version>_<arch>.deb,
# of everything `cmake --install` puts under the prefix (/usr): the three tools (component tools)
# and the prtshade run-time library with its loader, headers, shader mirrors and CMake package
# (component prtshade). Depends are what dpkg-shlibdeps finds the tools linked against; the -dev
# packages a program built against the static loader needs are Suggests.
set(CPACK_PACKAGE_NAME prtbake)
set(CPACK_PACKAGE_VENDOR "prtbake")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}: prtbake, prtdump, prtview and the prtshade run-time library")
set(CPACK_PACKAGE_DESCRIPTION [[
prtbake bakes per-vertex ambient occlusion, SH transfer vectors and band-1
shadowed radiance from an HDR environment into documented HDF5 files;
prtdump and prtview show them. prtshade shades them at run time: a std-only
C++20 library with a C API, GLSL and HLSL mirrors in /usr/share/prtshade,
and an optional .prt.h5 loader (find_package(prtshade COMPONENTS hdf5)).]])
set(PRT_DEB_MAINTAINER "prtbake maintainers <maintainers@users.noreply.h-seed-610fe6f1.example>"
    CACHE STRING "The Maintainer field of the .deb made by cpack -G DEB")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${PRT_DEB_MAINTAINER}")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # prtbake_0.1.0_amd64.deb
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_STRIP_FILES ON)
list(JOIN PRTSHADE_HDF5_DEBIAN_PACKAGES ", " suggests)
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "${suggests}")
set(CPACK_GENERATOR DEB)
include(CPack)
