# Finds the libraries CrossRT's libraries and runtime link to. Shared by the build tree and the
# installed package (CrossRTConfig.cmake includes this file).
include_guard(GLOBAL)
# Imported targets must be visible to a parent project that add_subdirectory()s CrossRT.
set(CMAKE_FIND_PACKAGE_TARGETS_GLOBAL ON)
find_package(Threads REQUIRED)
find_package(Vulkan REQUIRED COMPONENTS glslangValidator)
find_package(embree 3 REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)

find_package(OpenImageIO 2.4 CONFIG REQUIRED)
# Debian's OpenImageIO config lists /usr/include/opencv4, which does not exist: drop it.
get_target_property(_crossrt_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
if(_crossrt_oiio_inc)
  list(FILTER _crossrt_oiio_inc EXCLUDE REGEX "opencv4")
  set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_crossrt_oiio_inc}")
endif()

# Mesh files (OFF, PLY, OBJ) for litemesh; zlib reads gzipped ones.
find_package(assimp CONFIG REQUIRED)
find_package(ZLIB REQUIRED)
