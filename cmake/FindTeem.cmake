# Debian's libteem-dev ships a CMake config whose library location is the package's build folder,
# so find the header and library directly and expose one imported target, Teem::teem (NRRD IO).
find_path(TEEM_INCLUDE_DIR teem/nrrd.h REQUIRED)
find_library(TEEM_LIBRARY teem REQUIRED)
if(NOT TARGET Teem::teem)
  add_library(Teem::teem UNKNOWN IMPORTED)
  set_target_properties(Teem::teem PROPERTIES
    IMPORTED_LOCATION "${TEEM_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${TEEM_INCLUDE_DIR}")
endif()
message(STATUS "teem: ${TEEM_LIBRARY} (headers ${TEEM_INCLUDE_DIR})")
