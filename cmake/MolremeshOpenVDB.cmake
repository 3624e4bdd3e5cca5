# OpenVDB (Debian's libopenvdb-dev) behind one INTERFACE target, molremesh_openvdb, for the code
# that includes vcg_ext/volume/ headers. The rest of vcg_ext never sees OpenVDB. openvdb_libraries
# is the same without vcg_ext (whose vcglib is Debian's), for the MeshLab 2023.12 plugin.
#
# Debian installs OpenVDB's FindOpenVDB.cmake (it searches Blosc, OpenEXR, log4cplus ... for
# options we do not use), so a plain search for the header and the shared library is enough: the
# library links its own dependencies; we add TBB and Imath, whose headers OpenVDB's headers include.
find_path(OPENVDB_INCLUDE_DIR openvdb/openvdb.h)
find_library(OPENVDB_LIBRARY NAMES openvdb)
find_package(TBB REQUIRED)
find_package(Imath QUIET)
if(NOT OPENVDB_INCLUDE_DIR OR NOT OPENVDB_LIBRARY)
  message(FATAL_ERROR "OpenVDB not found: install Debian's 'libopenvdb-dev' (scripts/install_deps.sh)")
endif()
add_library(openvdb_libraries INTERFACE)
target_include_directories(openvdb_libraries SYSTEM INTERFACE ${OPENVDB_INCLUDE_DIR})
target_link_libraries(openvdb_libraries INTERFACE ${OPENVDB_LIBRARY} TBB::tbb)
if(TARGET Imath::Imath)
  target_link_libraries(openvdb_libraries INTERFACE Imath::Imath)
endif()
# What links the volume layer may call it: the clean stage's volumetric fallback is compiled in only
# there (vcg_ext/clean/volumetric_fallback.h). Every translation unit of a target must agree on it
# (the pipeline's inline templates differ with it), so it goes on the whole target.
target_compile_definitions(openvdb_libraries INTERFACE MOLREMESH_HAVE_OPENVDB=1)
add_library(molremesh_openvdb INTERFACE)
target_link_libraries(molremesh_openvdb INTERFACE vcg_ext openvdb_libraries)
