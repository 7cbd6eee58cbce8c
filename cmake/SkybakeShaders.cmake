# skybake_embed_glsl(TARGET target DIR dir HEADER name NAMESPACE ns [SHARED file...])
#
# Embeds every DIR/NAME.glsl as the C++ string constant ns::NAME in the
# generated header ${PROJECT_BINARY_DIR}/include/<HEADER>, which TARGET may
# include (as "<HEADER>"); the header is regenerated when a shader changes.
# SHARED names files written in the common subset of C++ and GLSL (see
# src/core/shared_source.h), which C++ includes as headers: each is embedded
# as well, as ns::NAME after its file name without the extension.
function(skybake_embed_glsl)
  cmake_parse_arguments(E "" "TARGET;DIR;HEADER;NAMESPACE" "SHARED" ${ARGN})
  if(NOT TARGET ${E_TARGET})
    return()
  endif()
  file(GLOB glsl CONFIGURE_DEPENDS ${E_DIR}/*.glsl)
  set(out ${PROJECT_BINARY_DIR}/include/${E_HEADER})
  string(REPLACE ";" "|" shared "${E_SHARED}")
  add_custom_command(OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} -DDIR=${E_DIR} -DNAMESPACE=${E_NAMESPACE} "-DSHARED=${shared}"
            -P ${PROJECT_SOURCE_DIR}/cmake/embed_glsl.cmake
    DEPENDS ${glsl} ${E_SHARED} ${PROJECT_SOURCE_DIR}/cmake/embed_glsl.cmake
    COMMENT "Embedding GLSL shaders of ${E_TARGET}"
    VERBATIM)
  add_custom_target(${E_TARGET}_shaders DEPENDS ${out})
  add_dependencies(${E_TARGET} ${E_TARGET}_shaders)
  target_include_directories(${E_TARGET} PRIVATE ${PROJECT_BINARY_DIR}/include)
endfunction()
