# The library's layers, one static library per folder, and the compiler enforcing them.
#
# Each layer is compiled with an include path that holds only itself and the layers it declares,
# directly or through them: a folder of symbolic links, ${CMAKE_BINARY_DIR}/layers/<name>/<layer> ->
# the layer's sources. An `#include "render/camera.h"` in a layer that does not declare render
# (directly or below) then fails to compile with "No such file or directory": a wrong include breaks
# the build, not a review. The front ends (the CLI, the tests, the benchmarks) link `pneumo_lib`,
# which holds every layer and the whole include path.
#
#   pneumo_layer(NAME DIR <folder> [DEPS <layer>...] [SOURCES <extra source>...])
#
# A layer's DEPS must be declared before it; the order of the calls in CMakeLists.txt is therefore
# the layering, bottom first.

function(pneumo_layer name)
  cmake_parse_arguments(L "" "DIR" "DEPS;SOURCES" ${ARGN})
  if(NOT L_DIR)
    message(FATAL_ERROR "pneumo_layer(${name}): DIR is required")
  endif()
  set(closure ${name})
  foreach(dep IN LISTS L_DEPS)
    if(NOT TARGET pneumo_${dep})
      message(FATAL_ERROR "pneumo_layer(${name}): layer ${dep} is not declared yet (declare layers bottom first)")
    endif()
    get_property(dep_closure GLOBAL PROPERTY PNEUMO_LAYER_CLOSURE_${dep})
    list(APPEND closure ${dep_closure})
  endforeach()
  list(REMOVE_DUPLICATES closure)
  set_property(GLOBAL PROPERTY PNEUMO_LAYER_CLOSURE_${name} ${closure})
  set_property(GLOBAL PROPERTY PNEUMO_LAYER_DIR_${name} ${L_DIR})

  # The include path of this layer: a link per visible layer, named as the includes spell it.
  set(view ${CMAKE_BINARY_DIR}/layers/${name})
  file(REMOVE_RECURSE ${view})
  file(MAKE_DIRECTORY ${view})
  foreach(visible IN LISTS closure)
    get_property(dir GLOBAL PROPERTY PNEUMO_LAYER_DIR_${visible})
    get_filename_component(link_name ${dir} NAME)
    file(CREATE_LINK ${dir} ${view}/${link_name} SYMBOLIC)
  endforeach()

  file(GLOB sources CONFIGURE_DEPENDS ${L_DIR}/*.cpp)
  if(sources OR L_SOURCES)
    add_library(pneumo_${name} STATIC ${sources} ${L_SOURCES})
    target_include_directories(pneumo_${name} PRIVATE ${view})
    set(scope PUBLIC)
  else()
    add_library(pneumo_${name} INTERFACE)   # headers only: nothing to compile, only a place in the order
    set(scope INTERFACE)
  endif()
  target_link_libraries(pneumo_${name} ${scope} pneumo_external)
  foreach(dep IN LISTS L_DEPS)
    target_link_libraries(pneumo_${name} ${scope} pneumo_${dep})
  endforeach()
  set_property(GLOBAL APPEND PROPERTY PNEUMO_LAYERS ${name})   # bottom first
endfunction()
