# Embeds every kernels/*.cl file into the library as a string, keyed by its path below kernels/
# (e.g. "common/math.cl"), so no path is needed at run time. The generated file is rebuilt
# whenever a kernel changes.
function(pneumo_embed_kernels out_cpp kernel_root)
  set(sources ${ARGN})
  # Passed as one argument: a list joined by "|" (a ";" would split the command line).
  string(REPLACE ";" "|" joined "${sources}")
  add_custom_command(
    OUTPUT ${out_cpp}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out_cpp} -DROOT=${kernel_root} "-DSOURCES=${joined}"
            -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/EmbedKernelsScript.cmake
    DEPENDS ${sources} ${CMAKE_CURRENT_SOURCE_DIR}/cmake/EmbedKernelsScript.cmake
    COMMENT "Embedding OpenCL kernels"
    VERBATIM)
endfunction()

# The same for GLSL shaders (shaders/*.vert, *.frag): table pneumo::gl::embedded_shaders().
function(pneumo_embed_shaders out_cpp shader_root)
  set(sources ${ARGN})
  string(REPLACE ";" "|" joined "${sources}")
  add_custom_command(
    OUTPUT ${out_cpp}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out_cpp} -DROOT=${shader_root} "-DSOURCES=${joined}"
            -DHEADER=render/embedded_shaders.h -DNAMESPACE=pneumo::gl -DTYPE=EmbeddedShader
            -DFUNC=embedded_shaders
            -P ${CMAKE_CURRENT_SOURCE_DIR}/cmake/EmbedKernelsScript.cmake
    DEPENDS ${sources} ${CMAKE_CURRENT_SOURCE_DIR}/cmake/EmbedKernelsScript.cmake
    COMMENT "Embedding GLSL shaders"
    VERBATIM)
endfunction()
