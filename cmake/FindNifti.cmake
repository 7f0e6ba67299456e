# Debian's libnifti2-dev ships a CMake config that points at a non-multiarch path, so find the
# header and libraries directly and expose one imported target, Nifti::nifti2.
find_path(NIFTI_INCLUDE_DIR nifti2_io.h PATH_SUFFIXES nifti REQUIRED)
find_library(NIFTI2_LIBRARY nifti2 REQUIRED)
find_library(ZNZ_LIBRARY znz REQUIRED)
find_package(ZLIB REQUIRED)
if(NOT TARGET Nifti::nifti2)
  add_library(Nifti::nifti2 UNKNOWN IMPORTED)
  set_target_properties(Nifti::nifti2 PROPERTIES
    IMPORTED_LOCATION "${NIFTI2_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${NIFTI_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${ZNZ_LIBRARY};ZLIB::ZLIB;m")
endif()
message(STATUS "niftilib: ${NIFTI2_LIBRARY} (headers ${NIFTI_INCLUDE_DIR})")
