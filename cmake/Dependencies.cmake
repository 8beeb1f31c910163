# Every dependency comes from a Debian 12 package; a missing one stops configure and names it.
macro(pt_require package debian)
  find_package(${package} ${ARGN} QUIET)
  if(NOT ${package}_FOUND)
    message(FATAL_ERROR "pt: ${package} not found. Install it with: apt-get install ${debian}"
                        "  (or run: bash cmake/setup.sh)")
  endif()
endmacro()

pt_require(embree libembree-dev 3.13)
pt_require(TBB libtbb-dev)
pt_require(OpenImageIO libopenimageio-dev)
pt_require(OpenEXR libopenexr-dev)
pt_require(tinyobjloader libtinyobjloader-dev)
pt_require(CLI11 libcli11-dev)
pt_require(nlohmann_json nlohmann-json3-dev)
pt_require(TinyGLTF libtinygltf-dev)
pt_require(draco libdraco-dev)
pt_require(Threads libc6-dev)
if(PT_BUILD_TESTS)
  pt_require(doctest doctest-dev)
endif()

# Debian 12's OpenImageIO config lists /usr/include/opencv4 among its include folders although
# libopenimageio-dev does not need OpenCV's headers; drop folders that do not exist rather than
# pull in libopencv-dev.
get_target_property(_oiio_includes OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
if(_oiio_includes)
  set(_kept "")
  foreach(_dir IN LISTS _oiio_includes)
    if(EXISTS "${_dir}" OR _dir MATCHES "^\\$<")
      list(APPEND _kept "${_dir}")
    endif()
  endforeach()
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_kept}")
endif()
