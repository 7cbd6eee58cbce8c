# The planet renderer and the viewer (src/render/), on the OpenGL layer (src/gl/).
# GLSL sources are embedded as C++ string literals: src/render/shaders/NAME.glsl
# becomes the constant skybake::render::shaders::NAME in render/shaders.h, and
# so does each file shared by C++ and GLSL (SHARED, see core/shared_source.h).
#
# The window (GLFW and Dear ImGui) is optional: without glfw3 or imgui, or
# without the sources of Dear ImGui's GLFW and OpenGL 3 backends (Debian's
# libimgui-dev installs them as examples), the window files compile to stubs
# that throw one error line, and everything headless still builds.
pkg_check_modules(GLFW IMPORTED_TARGET glfw3)
pkg_check_modules(IMGUI IMPORTED_TARGET imgui)
set(SKYBAKE_IMGUI_BACKENDS_DIR /usr/share/doc/libimgui-dev/examples/backends
  CACHE PATH "Folder holding Dear ImGui's imgui_impl_glfw.cpp and imgui_impl_opengl3.cpp")
set(SKYBAKE_HAS_WINDOW OFF CACHE INTERNAL "")
find_path(SKYBAKE_IMGUI_BACKENDS_INCLUDE imgui_impl_glfw.h HINTS ${IMGUI_INCLUDE_DIRS} PATH_SUFFIXES backends)
if(GLFW_FOUND AND IMGUI_FOUND AND SKYBAKE_IMGUI_BACKENDS_INCLUDE AND EXISTS ${SKYBAKE_IMGUI_BACKENDS_DIR}/imgui_impl_glfw.cpp
   AND EXISTS ${SKYBAKE_IMGUI_BACKENDS_DIR}/imgui_impl_opengl3.cpp)
  set(SKYBAKE_HAS_WINDOW ON CACHE INTERNAL "")
  # The backends are compiled from where the package installed them, not copied.
  add_library(skybake_imgui_backends STATIC ${SKYBAKE_IMGUI_BACKENDS_DIR}/imgui_impl_glfw.cpp
    ${SKYBAKE_IMGUI_BACKENDS_DIR}/imgui_impl_opengl3.cpp)
  target_include_directories(skybake_imgui_backends SYSTEM PUBLIC ${SKYBAKE_IMGUI_BACKENDS_INCLUDE})
  target_link_libraries(skybake_imgui_backends PUBLIC PkgConfig::IMGUI PkgConfig::GLFW ${CMAKE_DL_LIBS})
  set_target_properties(skybake_imgui_backends PROPERTIES POSITION_INDEPENDENT_CODE ON)
  message(STATUS "skybake: viewer window on (GLFW ${GLFW_VERSION}, Dear ImGui ${IMGUI_VERSION})")
else()
  message(STATUS "skybake: viewer window off (needs glfw3, imgui and the ImGui backend sources in "
    "${SKYBAKE_IMGUI_BACKENDS_DIR}); skybake view renders headless only")
endif()
if(SKYBAKE_HAS_WINDOW)
  skybake_add_module(render DEPENDS core io gl sphere visibility bake sky neural prt planet
    LIBS fmt::fmt skybake_imgui_backends)
  target_compile_definitions(skybake_render PRIVATE SKYBAKE_HAS_WINDOW=1)
else()
  skybake_add_module(render DEPENDS core io gl sphere visibility bake sky neural prt planet LIBS fmt::fmt)
endif()
skybake_embed_glsl(TARGET skybake_render DIR ${CMAKE_CURRENT_SOURCE_DIR}/render/shaders
  HEADER render/shaders.h NAMESPACE skybake::render::shaders
  SHARED ${CMAKE_CURRENT_SOURCE_DIR}/core/tone_curve.h ${CMAKE_CURRENT_SOURCE_DIR}/sky/grid4_shared.h
         ${CMAKE_CURRENT_SOURCE_DIR}/sky/sky_shared.h ${CMAKE_CURRENT_SOURCE_DIR}/sky/shade_shared.h)
