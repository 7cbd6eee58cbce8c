# The planet renderer and the viewer (src/render/), on the OpenGL layer (src/gl/).
# GLSL sources are embedded as C++ string literals: src/render/shaders/NAME.glsl
# becomes the constant skybake::render::shaders::NAME in render/shaders.h.
pkg_check_modules(GLFW REQUIRED IMPORTED_TARGET glfw3)
skybake_add_module(render DEPENDS core io gl sphere visibility bake sky neural prt planet
  LIBS fmt::fmt PkgConfig::GLFW)
skybake_embed_glsl(TARGET skybake_render DIR ${CMAKE_CURRENT_SOURCE_DIR}/render/shaders
  HEADER render/shaders.h NAMESPACE skybake::render::shaders)
