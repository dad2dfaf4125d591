# SPDX-License-Identifier: Apache-2.0
# Install rules: the libraries, the public headers (not *_internal.h), the ao command, the CMake
# package (aoConfig.cmake, aoConfigVersion.cmake, aoTargets.cmake: find_package(ao 0.2)), a
# pkg-config file (ao.pc) and the licence with its notice (share/doc/ao/). export() makes the same
# targets usable from the build tree.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(AO_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/ao)
install(TARGETS ao_core ao_lib EXPORT aoTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(AO_BUILD_CLI)
  install(TARGETS ao RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
# The GPU backend's shaders as readable files (docs/gpu.md), for engines that take one: the library
# itself carries them embedded and never reads these.
if(AO_GPU)
  install(FILES ${AO_GPU_SHADERS} DESTINATION ${CMAKE_INSTALL_DATADIR}/ao/shaders)
endif()
# Apache-2.0 section 4: a redistribution carries the licence and the NOTICE file.
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/NOTICE DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(EXPORT aoTargets NAMESPACE ao:: DESTINATION ${AO_CMAKE_DIR})
export(EXPORT aoTargets NAMESPACE ao:: FILE ${PROJECT_BINARY_DIR}/aoTargets.cmake)

if(BUILD_SHARED_LIBS)
  set(BUILD_SHARED_LIBS_BOOL TRUE)
else()
  set(BUILD_SHARED_LIBS_BOOL FALSE)
endif()
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/aoConfig.cmake.in ${PROJECT_BINARY_DIR}/aoConfig.cmake
                              INSTALL_DESTINATION ${AO_CMAKE_DIR})
# 0.x: a minor version may change the API, so find_package(ao 0.2) accepts 0.2.* only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/aoConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/aoConfig.cmake ${PROJECT_BINARY_DIR}/aoConfigVersion.cmake DESTINATION ${AO_CMAKE_DIR})

# pkg-config: the public headers need tbb and nlohmann_json; a static libao also needs the
# libraries it uses inside (Embree has no .pc file in Debian, hence -lembree3).
set(AO_PC_REQUIRES "tbb nlohmann_json")
if(BUILD_SHARED_LIBS)
  set(AO_PC_REQUIRES_PRIVATE "libhwy assimp OpenEXR libpng libtiff-4 libjpeg freetype2 libcrypto")
  set(AO_PC_LIBS "")
else()
  set(AO_PC_REQUIRES "${AO_PC_REQUIRES} libhwy assimp OpenEXR libpng libtiff-4 libjpeg freetype2 libcrypto")
  set(AO_PC_REQUIRES_PRIVATE "")
  set(AO_PC_LIBS "-lembree3 -pthread")
  if(AO_GPU AND CMAKE_DL_LIBS)
    string(APPEND AO_PC_LIBS " -l${CMAKE_DL_LIBS}")  # the GPU backend opens libEGL at run time (dlopen)
  endif()
endif()
# The prefix relative to the .pc file's folder, so that the package can be installed anywhere
# (cmake --install --prefix P) and moved.
file(RELATIVE_PATH AO_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" AO_PC_TO_PREFIX "${AO_PC_TO_PREFIX}")
configure_file(${CMAKE_CURRENT_LIST_DIR}/ao.pc.in ${PROJECT_BINARY_DIR}/ao.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/ao.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
