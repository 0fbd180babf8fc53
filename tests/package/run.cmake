# ctest Package.InstalledLibraryBuildsAndRuns: installs the build tree into a fresh prefix, builds
# tests/package against it with nothing of the source or build tree on its paths, and runs it.
# -D BUILD_DIR=... -D SOURCE_DIR=... -D WORK_DIR=... -D SCENE=... [-D PYTHON=/usr/bin/python3]
file(REMOVE_RECURSE "${WORK_DIR}")
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix"
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "cmake --install failed: ${rc}")
endif()
foreach(f include/whitted/whitted.h lib/cmake/whitted/whittedConfig.cmake lib/cmake/whitted/whittedConfigVersion.cmake
          bin/whitted share/whitted/ocio/config.ocio share/whitted/environments/studio.exr
          lib/whitted/libwhitted_oiio.so)
  if(NOT EXISTS "${WORK_DIR}/prefix/${f}")
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/package" -B "${WORK_DIR}/build" -G Ninja
                        -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix"
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer against the installed package failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build "${WORK_DIR}/build" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the consumer failed")
endif()
# Run with no source tree to fall back on: the OCIO config must come from the prefix.
execute_process(COMMAND ${CMAKE_COMMAND} -E env WHITTED_DATA_DIR= "${WORK_DIR}/build/consumer" "${SCENE}"
                        "${WORK_DIR}/out.png" RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message("${out}")
if(rc)
  message(FATAL_ERROR "the consumer failed: ${rc}")
endif()
if(NOT out MATCHES "OCIO config: ${WORK_DIR}/prefix/share/whitted/ocio/config.ocio")
  message(FATAL_ERROR "the installed library did not find its own data in the prefix")
endif()
# A JPEG is written in process; reading the PNG back goes through the image module
# (OpenImageIO), installed beside the library.
execute_process(COMMAND ${CMAKE_COMMAND} -E env WHITTED_DATA_DIR= WHITTED_IMAGE_MODULE=${WORK_DIR}/prefix/lib/whitted/libwhitted_oiio.so
                        "${WORK_DIR}/build/consumer" "${SCENE}" "${WORK_DIR}/out.jpg" "${WORK_DIR}/out.png"
                        RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(rc OR NOT EXISTS "${WORK_DIR}/out.jpg" OR NOT out MATCHES "read ${WORK_DIR}/out.png: 48x")
  message(FATAL_ERROR "the consumer could not write a JPEG or read a PNG through the installed image module: ${rc} ${out}")
endif()
# The Python module from the prefix (when it was built): imports, renders, finds its data there.
if(PYTHON)
  file(GLOB site "${WORK_DIR}/prefix/lib/python3*/site-packages")
  execute_process(COMMAND ${CMAKE_COMMAND} -E env "PYTHONPATH=${site}" WHITTED_DATA_DIR= ${PYTHON} -c
      "import whitted; s = whitted.load('${SCENE}'); i = whitted.render(s, width=32); print(whitted._data_file('ocio/config.ocio'), i.beauty.shape)"
      RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  message("${out}")
  if(rc OR NOT out MATCHES "^${WORK_DIR}/prefix/share/whitted/ocio/config.ocio")
    message(FATAL_ERROR "the installed Python module failed or did not find its data in the prefix")
  endif()
endif()
if(NOT EXISTS "${WORK_DIR}/out.png")
  message(FATAL_ERROR "the consumer wrote no image")
endif()
