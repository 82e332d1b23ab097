# The installable part of sdfstream: the libraries an engine links (core, shaders, gpu, world,
# raster, objects, cards, streaming, gi), their headers, and a CMake package so that
#   find_package(sdfstream CONFIG REQUIRED)
#   target_link_libraries(engine PRIVATE sdfstream::gi)
# works from an install prefix. Headers are included as "module/file.h" in both trees: from the
# source root in the build tree, from <prefix>/include/sdfstream once installed.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SDFSTREAM_INSTALL_INCLUDE_DIR "${CMAKE_INSTALL_INCLUDEDIR}/sdfstream")
set(SDFSTREAM_INSTALL_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/sdfstream")
set(sdfstream_library_modules core shaders gpu world raster objects cards streaming gi)

foreach(module IN LISTS sdfstream_library_modules)
  set(target sdfstream_${module})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:${SDFSTREAM_INSTALL_INCLUDE_DIR}>)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${module} POSITION_INDEPENDENT_CODE ON)
  add_library(sdfstream::${module} ALIAS ${target})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${module}/ DESTINATION ${SDFSTREAM_INSTALL_INCLUDE_DIR}/${module}
          FILES_MATCHING PATTERN "*.h")
endforeach()

install(TARGETS sdfstream_core sdfstream_shaders sdfstream_gpu sdfstream_world sdfstream_raster
                sdfstream_objects
                sdfstream_cards sdfstream_streaming sdfstream_gi
        EXPORT sdfstreamTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${SDFSTREAM_INSTALL_INCLUDE_DIR})
install(EXPORT sdfstreamTargets NAMESPACE sdfstream:: DESTINATION ${SDFSTREAM_INSTALL_CMAKE_DIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/sdfstreamConfig.cmake.in
  ${PROJECT_BINARY_DIR}/sdfstreamConfig.cmake INSTALL_DESTINATION ${SDFSTREAM_INSTALL_CMAKE_DIR}
  PATH_VARS SDFSTREAM_INSTALL_INCLUDE_DIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/sdfstreamConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/sdfstreamConfig.cmake
              ${PROJECT_BINARY_DIR}/sdfstreamConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/FindOpenVDBModule.cmake
        DESTINATION ${SDFSTREAM_INSTALL_CMAKE_DIR})
