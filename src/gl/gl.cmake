# The OpenGL layer (src/gl/): the only place that includes GL or EGL headers
# (GLFW: src/render/viewer.cpp). GL functions are loaded with libepoxy;
# contexts are headless EGL (surfaceless or device platform) or a GLFW window.
find_package(PkgConfig REQUIRED)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
skybake_add_module(gl DEPENDS core LIBS fmt::fmt PkgConfig::EGL PUBLIC_LIBS PkgConfig::EPOXY)
