# The installed engine include is self-contained: install the sdfstream_glsl component alone into
# PREFIX, copy the engine test shader SHADER into an empty folder beside it and compile it with
# only PREFIX/include on glslang's path, once with the defaults the shader leaves alone overridden
# (-DSDFSTREAM_PROBE_SET=2); with SPIRV_DIS, check that the override reached the descriptors.
#   cmake -DBUILD_DIR=... -DPREFIX=... -DSHADER=... -DGLSLANG=... [-DSPIRV_DIS=...] -P this
file(REMOVE_RECURSE "${PREFIX}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}"
                        --component sdfstream_glsl
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "install of the sdfstream_glsl component failed:\n${out}")
endif()
file(COPY "${SHADER}" DESTINATION "${PREFIX}/engine")
get_filename_component(name "${SHADER}" NAME)
execute_process(COMMAND "${GLSLANG}" -V --target-env vulkan1.2 -I${PREFIX}/include
                        -DSDFSTREAM_PROBE_SET=2 -o "${PREFIX}/engine/engine.spv"
                        "${PREFIX}/engine/${name}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${name} does not compile against the installed include alone:\n${out}")
endif()
if(SPIRV_DIS)
  execute_process(COMMAND "${SPIRV_DIS}" "${PREFIX}/engine/engine.spv"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE asm ERROR_VARIABLE err)
  string(REGEX MATCHALL "DescriptorSet 2" set2 "${asm}")
  list(LENGTH set2 count)
  if(NOT rc EQUAL 0 OR NOT count EQUAL 8)
    message(FATAL_ERROR "expected the include's 8 buffers in set 2, found ${count}:\n${err}")
  endif()
endif()
file(GLOB_RECURSE installed RELATIVE "${PREFIX}" "${PREFIX}/include/*")
list(JOIN installed ", " installed)
message(STATUS "compiled ${name} against the install alone: ${installed}")
