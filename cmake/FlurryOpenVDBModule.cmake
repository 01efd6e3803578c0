# OpenVDB installs no package config file, only a find module: FindOpenVDB.cmake (with
# FindTBB.cmake, FindBlosc.cmake... next to it) in <prefix>/lib[/<arch>]/cmake/OpenVDB, a
# folder CMake does not search. This finds that folder under the prefixes CMake searches
# (CMAKE_PREFIX_PATH, OpenVDB_ROOT, the system prefixes) and appends it to CMAKE_MODULE_PATH, so
# find_package(OpenVDB) works wherever OpenVDB is installed. Used by Flurry's build and, as
# installed next to FlurryConfig.cmake, by its package when a static flurry::vdb needs OpenVDB.
# A FindOpenVDB module already on CMAKE_MODULE_PATH is kept; FLURRY_OPENVDB_MODULE_DIR (a cache
# entry) may name the folder, and FLURRY_OPENVDB_MODULE_HINTS adds places to look.
set(_flurry_openvdb_on_path OFF)
foreach(_flurry_dir IN LISTS CMAKE_MODULE_PATH)
  if(EXISTS "${_flurry_dir}/FindOpenVDB.cmake")
    set(_flurry_openvdb_on_path ON)
  endif()
endforeach()
if(NOT _flurry_openvdb_on_path)
  find_path(FLURRY_OPENVDB_MODULE_DIR FindOpenVDB.cmake
    HINTS ${FLURRY_OPENVDB_MODULE_HINTS} ${OpenVDB_ROOT} $ENV{OpenVDB_ROOT}
    PATHS ${CMAKE_PREFIX_PATH} ${CMAKE_SYSTEM_PREFIX_PATH}
    PATH_SUFFIXES lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB lib64/cmake/OpenVDB
                  lib/cmake/OpenVDB share/cmake/OpenVDB cmake/OpenVDB
    DOC "Folder holding OpenVDB's FindOpenVDB.cmake")
  if(FLURRY_OPENVDB_MODULE_DIR)
    list(APPEND CMAKE_MODULE_PATH "${FLURRY_OPENVDB_MODULE_DIR}")
  endif()
endif()
unset(_flurry_openvdb_on_path)
unset(_flurry_dir)
