# Every dependency comes from a Debian 12 package (see ../shared/STACK.md and docs/building.md).
find_package(embree 3 REQUIRED)
find_package(TBB REQUIRED)
find_package(OpenImageIO REQUIRED)
find_package(TinyGLTF REQUIRED)
find_package(CLI11 REQUIRED)
find_package(fmt REQUIRED)
find_package(PkgConfig REQUIRED)
# OpenColorIO's CMake config on Debian yields a broken include dir: use pkg-config.
pkg_check_modules(OCIO REQUIRED IMPORTED_TARGET OpenColorIO>=2.1)
# libdeflate (Debian: libdeflate-dev) compresses TIFF strips: one call per strip, 2-3x zlib's speed.
pkg_check_modules(DEFLATE REQUIRED IMPORTED_TARGET libdeflate)

# OIIO's exported target lists /usr/include/opencv4, which exists only with libopencv-dev and
# otherwise fails generation: drop entries that do not exist.
get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
if(_oiio_inc)
  set(_oiio_inc_ok "")
  foreach(_dir IN LISTS _oiio_inc)
    if(EXISTS "${_dir}")
      list(APPEND _oiio_inc_ok "${_dir}")
    endif()
  endforeach()
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_inc_ok}")
endif()
