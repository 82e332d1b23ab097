# The embedding example end to end, as an engine team would build it: install sdfstream into a
# fresh prefix, configure and build examples/embed against that prefix alone (find_package), make
# a small world, run the example, then compare its image with the blocking path's.
# -D BUILD_DIR, SOURCE_DIR, SDFSTREAM (the CLI), REFERENCE (embed_reference), WORK
function(step)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "embed example: '${ARGV}' failed (${rc})")
  endif()
endfunction()
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/out)
step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK}/prefix)
# An instrumented sdfstream (scripts/sanitize) needs an instrumented engine around it: the
# sanitizer flags come through the environment, as an engine's own build would set them.
set(engine_flags)
if(DEFINED ENV{SDFSTREAM_EMBED_SANITIZE})
  set(engine_flags "-DCMAKE_CXX_FLAGS=$ENV{SDFSTREAM_EMBED_SANITIZE}"
                   "-DCMAKE_EXE_LINKER_FLAGS=$ENV{SDFSTREAM_EMBED_SANITIZE}")
endif()
step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/embed -B ${WORK}/build -G Ninja
     -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK}/prefix ${engine_flags})
step(${CMAKE_COMMAND} --build ${WORK}/build)
step(${SDFSTREAM} import /usr/share/glmark2/models/bunny.obj -o ${WORK}/world --voxel 0.012
     --lods 3 --tile-voxels 64)
step(${WORK}/build/embed_example ${WORK}/world ${WORK}/out --frames 100 --settle)
step(${REFERENCE} ${WORK}/world ${WORK}/out/irradiance.pfm 100)
