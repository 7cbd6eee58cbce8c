# The OpenGL layer (src/render/): the only place that includes GL, EGL or
# GLFW headers. GL functions are loaded with libepoxy; contexts are headless
# EGL (surfaceless or device platform) or a GLFW window.
find_package(PkgConfig REQUIRED)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
pkg_check_modules(GLFW REQUIRED IMPORTED_TARGET glfw3)

# GLSL sources are embedded as C++ string literals: src/render/shaders/NAME.glsl
# becomes the constant skybake::render::shaders::NAME in render/shaders.h.
file(GLOB skybake_glsl CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/render/shaders/*.glsl)
set(skybake_shader_header ${PROJECT_BINARY_DIR}/include/render/shaders.h)
add_custom_command(OUTPUT ${skybake_shader_header}
  COMMAND ${CMAKE_COMMAND} -DOUT=${skybake_shader_header} -DDIR=${CMAKE_CURRENT_SOURCE_DIR}/render/shaders
          -P ${CMAKE_CURRENT_SOURCE_DIR}/render/embed_shaders.cmake
  DEPENDS ${skybake_glsl} ${CMAKE_CURRENT_SOURCE_DIR}/render/embed_shaders.cmake
  COMMENT "Embedding GLSL shaders")
add_custom_target(skybake_render_shaders DEPENDS ${skybake_shader_header})

skybake_add_module(render DEPENDS core io sky neural planet
  LIBS fmt::fmt PkgConfig::EPOXY PkgConfig::EGL PkgConfig::GLFW)
if(TARGET skybake_render)
  add_dependencies(skybake_render skybake_render_shaders)
  target_include_directories(skybake_render PRIVATE ${PROJECT_BINARY_DIR}/include)
endif()
