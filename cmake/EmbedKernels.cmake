# Embeds source files into the library as strings, keyed by their path below a root folder, so no
# path is needed at run time: the OpenCL kernels (kernels/*.cl, e.g. "common/math.cl"), the GLSL
# shaders (shaders/*) and the page of `pneumo serve` (host/serve/page/*). The generated file is
# rebuilt whenever one of them changes; cmake/EmbedKernelsScript.cmake writes it.
#
#   pneumo_embed(OUT_CPP ROOT HEADER NAMESPACE TYPE FUNC COMMENT SOURCES...)
#     a table `const std::vector<TYPE>& NAMESPACE::FUNC()` declared in HEADER
function(pneumo_embed out_cpp root header namespace type func comment)
  set(sources ${ARGN})
  # Passed as one argument: a list joined by "|" (a ";" would split the command line).
  string(REPLACE ";" "|" joined "${sources}")
  add_custom_command(
    OUTPUT ${out_cpp}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out_cpp} -DROOT=${root} "-DSOURCES=${joined}"
            -DHEADER=${header} -DNAMESPACE=${namespace} -DTYPE=${type} -DFUNC=${func}
            -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/EmbedKernelsScript.cmake
    DEPENDS ${sources} ${CMAKE_CURRENT_SOURCE_DIR}/cmake/EmbedKernelsScript.cmake
    COMMENT "${comment}"
    VERBATIM)
endfunction()

function(pneumo_embed_kernels out_cpp kernel_root)
  pneumo_embed(${out_cpp} ${kernel_root} cl/embedded_kernels.h pneumo::ocl EmbeddedKernel embedded_kernels
               "Embedding OpenCL kernels" ${ARGN})
endfunction()

function(pneumo_embed_shaders out_cpp shader_root)
  pneumo_embed(${out_cpp} ${shader_root} render/embedded_shaders.h pneumo::gl EmbeddedShader embedded_shaders
               "Embedding GLSL shaders" ${ARGN})
endfunction()

function(pneumo_embed_page out_cpp page_root)
  pneumo_embed(${out_cpp} ${page_root} serve/embedded_page.h pneumo::serve EmbeddedPageFile embedded_page
               "Embedding the serve page" ${ARGN})
endfunction()
