# OpenVDB ships its CMake support as a find module (FindOpenVDB.cmake) in a folder of its own
# rather than a package config. Look for that folder under the usual prefixes (and OpenVDB_ROOT,
# CMAKE_PREFIX_PATH) instead of naming one distribution's path, and put it on the module path.
# Used by the build and by the installed sdfstreamConfig.cmake alike.
if(NOT SDFSTREAM_OPENVDB_MODULE_DIR)
  find_path(SDFSTREAM_OPENVDB_MODULE_DIR FindOpenVDB.cmake
    HINTS ${OpenVDB_ROOT} $ENV{OpenVDB_ROOT}
    PATH_SUFFIXES lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB lib/cmake/OpenVDB
                  lib64/cmake/OpenVDB share/OpenVDB/cmake cmake/OpenVDB
    DOC "Folder holding OpenVDB's FindOpenVDB.cmake")
endif()
if(NOT SDFSTREAM_OPENVDB_MODULE_DIR)
  message(FATAL_ERROR "sdfstream: OpenVDB's FindOpenVDB.cmake was not found (Debian: libopenvdb-dev; "
                      "elsewhere set OpenVDB_ROOT or SDFSTREAM_OPENVDB_MODULE_DIR)")
endif()
list(APPEND CMAKE_MODULE_PATH "${SDFSTREAM_OPENVDB_MODULE_DIR}")
