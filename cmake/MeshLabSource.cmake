# Locates the sources of the installed MeshLab (plugin headers under src/, vcglib under vcglib/).
#
# They come from Debian's source package of the same version as the installed `meshlab`
# binary package, so the plugin is compiled against exactly the headers libmeshlab-common.so
# was built from. Nothing from MeshLab or vcglib is kept in this repository.
#
# Set MESHLAB_SOURCE_DIR to an unpacked tree to skip the download; otherwise it is fetched once
# into MOLREMESH_DEPS_DIR (default: <build>/_deps) by scripts/fetch_meshlab_source.sh.

set(MOLREMESH_DEPS_DIR "${CMAKE_BINARY_DIR}/_deps" CACHE PATH "Where downloaded source dependencies are cached")
set(MESHLAB_SOURCE_DIR "" CACHE PATH "Unpacked MeshLab source tree matching the installed MeshLab")

if(NOT MESHLAB_SOURCE_DIR)
  execute_process(
    COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/fetch_meshlab_source.sh ${MOLREMESH_DEPS_DIR}/meshlab-source
    RESULT_VARIABLE _fetch_result)
  if(NOT _fetch_result EQUAL 0)
    message(FATAL_ERROR "Could not fetch Debian's MeshLab source package (see the message above). "
                        "Install the 'meshlab' and 'dpkg-dev' packages, or set MESHLAB_SOURCE_DIR.")
  endif()
  set(MESHLAB_SOURCE_DIR "${MOLREMESH_DEPS_DIR}/meshlab-source/meshlab" CACHE PATH
      "Unpacked MeshLab source tree matching the installed MeshLab" FORCE)
endif()

set(VCGLIB_DIR "${MESHLAB_SOURCE_DIR}/vcglib")
foreach(_required src/common/interfaces.h vcglib/vcg/complex/complex.h)
  if(NOT EXISTS "${MESHLAB_SOURCE_DIR}/${_required}")
    message(FATAL_ERROR "MESHLAB_SOURCE_DIR=${MESHLAB_SOURCE_DIR} lacks ${_required}")
  endif()
endforeach()
message(STATUS "MeshLab source: ${MESHLAB_SOURCE_DIR}")
